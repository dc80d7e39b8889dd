"""Spec errors (issue 38): every problem of a file is reported, up to a cap, each on its own
line `FILE:LINE: field: message` at the line of the offending key; an unknown key gets "did
you mean ..." from the schema; a single problem keeps its one-line form."""

from __future__ import annotations

import pickle
from pathlib import Path

import pytest
from click.testing import CliRunner

from simkit.cli import main
from simkit.errors import SpecError
from simkit.spec.schema import RobotSpec
from simkit.spec.suggest import allowed_fields
from simkit.spec.validate import MAX_LISTED, load_spec

SPEC = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
GOOD = SPEC.read_text()
#: planar_2r's second link (links[1]): its entry line and its mass line
LINK = "  - name: link_1\n    mass: 1.0\n"


def _line(text: str, needle: str) -> int:
    """1-based line of the first line of `text` that equals `needle`."""
    return text.splitlines().index(needle) + 1


def _refusal(tmp_path: Path, text: str) -> SpecError:
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(SpecError) as info:
        load_spec(path, display="bad.yaml")
    return info.value


def test_typo_inside_a_link_gives_both_lines(tmp_path):
    assert LINK in GOOD
    text = GOOD.replace(LINK, "  - name: link_1\n    mas: 1.0\n")
    err = _refusal(tmp_path, text)
    assert str(err).splitlines() == [
        f"bad.yaml:{_line(text, '  - name: link_1')}: links[1].mass: required field is missing",
        f"bad.yaml:{_line(text, '    mas: 1.0')}: links[1].mas: unknown field; "
        "did you mean 'mass'?",
    ]


def test_cli_prints_each_problem_on_its_own_line(tmp_path):
    (tmp_path / "bad.yaml").write_text(GOOD.replace(LINK, "  - name: link_1\n    mas: 1.0\n"))
    run = CliRunner().invoke(main, ["build", str(tmp_path / "bad.yaml"), "--no-cache"])
    lines = run.output.strip().splitlines()
    assert run.exit_code == SpecError.exit_code
    assert lines[-2].startswith("simkit: error: ") and "links[1].mass: required" in lines[-2]
    assert lines[-1].endswith("links[1].mas: unknown field; did you mean 'mass'?")


def test_one_problem_keeps_its_one_line(tmp_path):
    text = GOOD.replace(LINK, "  - name: link_1\n    mass: -7.2\n")
    err = _refusal(tmp_path, text)
    line = _line(text, "    mass: -7.2")
    assert str(err) == f"bad.yaml:{line}: links[1].mass: mass must be > 0 kg (got -7.2)"
    assert (err.line, err.field, err.others) == (line, "links[1].mass", ())


def test_unknown_key_far_from_any_field_gets_no_guess(tmp_path):
    text = GOOD.replace("title: Planar 2R\n", "title: Planar 2R\nzzzzqq: 1\n")
    err = _refusal(tmp_path, text)
    assert str(err) == f"bad.yaml:{_line(text, 'zzzzqq: 1')}: zzzzqq: unknown field"


def test_did_you_mean_follows_the_schema_at_that_level(tmp_path):
    text = GOOD.replace(
        "    axis: [0, 0, 1]\n    lower_deg: -170", "    axis: [0, 0, 1]\n    lowr_deg: -170"
    )
    text = text.replace("title: Planar 2R\n", "titel: Planar 2R\n")
    lines = str(_refusal(tmp_path, text)).splitlines()
    assert (
        f"bad.yaml:{_line(text, 'titel: Planar 2R')}: titel: unknown field; did you mean 'title'?"
        in lines
    )
    joint = _line(text, "    lowr_deg: -170")
    guess = "unknown field; did you mean 'lower_deg'?"
    assert f"bad.yaml:{joint}: joints[1].lowr_deg: {guess}" in lines
    # the schema's YAML names, aliases included, at each level
    assert "from" in allowed_fields(RobotSpec, ("links", 0, "solid", 0))
    assert "mass" in allowed_fields(RobotSpec, ("links", 3)) and "name" not in allowed_fields(
        RobotSpec, ("published",)
    )


def test_problems_beyond_the_cap_are_counted(tmp_path):
    extra = "".join(f"unknown_{k:02d}: 1\n" for k in range(MAX_LISTED + 5))
    err = _refusal(tmp_path, GOOD + extra)
    lines = str(err).splitlines()
    assert len(lines) == MAX_LISTED + 1 and lines[-1] == "(and 5 more errors not shown)"
    first = len(GOOD.splitlines()) + 1
    assert lines[0] == f"bad.yaml:{first}: unknown_00: unknown field"
    assert lines[MAX_LISTED - 1].startswith(f"bad.yaml:{first + MAX_LISTED - 1}: unknown_19: ")


def test_a_listed_error_crosses_processes_whole():
    err = SpecError("a.yaml", 3, "x", "bad", more=2, others=((4, "y", "worse"),))
    again = pickle.loads(pickle.dumps(err))
    assert (
        str(again)
        == str(err)
        == ("a.yaml:3: x: bad\na.yaml:4: y: worse\n(and 2 more errors not shown)")
    )
