"""Check failures name what failed (issue 38): the entity (joint or link), expected, actual,
tolerance and unit; never "expected 7 values, got 7 values"."""

from __future__ import annotations

import numpy as np

from simkit.check.findings import LISTED_FAILURES, compare, failure_message, require
from simkit.check.published_numbers import explain
from simkit.spec.load import SourceDoc

JOINTS = [f"J{i}" for i in range(1, 8)]


def test_a_long_vector_shows_its_worst_entry_by_name():
    expected = np.full(7, 1.5708)
    actual = expected.copy()
    actual[2] = 1.6
    line = compare("mjcf.range", "joint ranges", expected, actual, 1e-6, "rad", JOINTS).line()
    assert line == (
        "FAIL mjcf.range: joint ranges (worst error 0.0292 rad, 7 values): "
        "J3: expected 1.5708, got 1.6 (tolerance 1e-06 rad)"
    )
    assert "7 values, got" not in line


def test_a_per_link_row_is_shown_whole():
    expected = np.zeros((8, 3))
    actual = expected.copy()
    actual[5, 1] = 0.002
    names = [f"link_{k}" for k in range(8)]
    finding = compare("com.mjcf", "CoM per link", expected, actual, 1e-6, "m", names)
    assert not finding.ok
    assert finding.detail.endswith(": link_5")
    assert (finding.expected, finding.actual) == ("(0, 0, 0)", "(0, 0.002, 0)")
    assert (finding.tolerance, finding.unit) == ("1e-06", "m")


def test_a_short_vector_names_its_worst_entry():
    finding = compare("mass.urdf", "per-link mass", [1, 2, 3], [1, 2.5, 3], 1e-6, "kg", "abc")
    assert finding.line() == (
        "FAIL mass.urdf: per-link mass (worst error 0.5 kg at b): expected (1, 2, 3), "
        "got (1, 2.5, 3) (tolerance 1e-06 kg)"
    )


def test_without_labels_the_index_is_named_and_nan_is_the_worst():
    actual = np.zeros(10)
    actual[9] = np.nan
    finding = compare("x.y", "values", np.zeros(10), actual, 1e-6, "m")
    assert not finding.ok
    assert finding.line().endswith("[9]: expected 0, got nan (tolerance 1e-06 m)")


def test_a_scalar_reads_as_before():
    finding = compare("published.mass", "sum of link masses", 29.3, 29.8, 0.01, "kg")
    assert finding.line() == (
        "FAIL published.mass: sum of link masses (worst error 0.5 kg): expected 29.3, "
        "got 29.8 (tolerance 0.01 kg)"
    )


def test_a_published_failure_names_the_spec_line_and_what_to_do():
    doc = SourceDoc("robots/r.yaml", {}, {("published",): 29, ("published", "mass"): 30}, "")
    failed = compare("published.mass", "sum of link masses", 29.3, 29.8, 0.01, "kg")
    assert explain(failed, doc) == (
        "robots/r.yaml:30: published.mass: the spec publishes 29.3 kg, the model gives 29.8 kg "
        "(sum of link masses; tolerance 0.01 kg): correct that line, or build again with "
        "--accept-published to write the model's value there"
    )
    other = compare("mass.urdf", "per-link mass", [1.0], [2.0], 1e-6, "kg")
    assert explain(other, doc) is None
    assert explain(compare("published.mass", "sum", 29.3, 29.3, 0.01, "kg"), doc) is None


def test_a_failed_build_lists_each_failure_on_its_own_line():
    failed = [require(f"c{k}", False, f"problem {k}") for k in range(LISTED_FAILURES + 2)]
    text = failure_message("r", failed, lambda f: "explained" if f.check == "c1" else None)
    lines = text.splitlines()
    assert lines[0] == f"r: {LISTED_FAILURES + 2} check(s) failed:"
    assert lines[1] == "  FAIL c0: problem 0" and lines[2] == "  explained"
    assert len(lines) == LISTED_FAILURES + 2 and lines[-1].startswith("  (and 2 more")
