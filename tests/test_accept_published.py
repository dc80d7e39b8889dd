"""A spec edit is a supported workflow (issue 38): a published.* failure names the spec's
line and what to do; `simkit build PATH --accept-published` rewrites only the published
values that disagree (every other byte kept), prints each change, and the spec then builds."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from simkit.cli import main
from simkit.cli.accepting import installed_spec
from simkit.errors import CheckFailed
from simkit.pipeline import build
from simkit.spec.published_edit import rewrite_published, spelled

REPO = Path(__file__).resolve().parents[1]
TEXT = """name: r  # a comment
published:
  mass: 29.3                  # kg (kit page table)
  tool0_home: [0.330, 0.0, 0.423]   # m
  base_link_height: 0.175
  reach:
    - 0.5
    - 0.6
links: []
"""


def test_only_the_disagreeing_values_change_and_comments_keep_their_column():
    values = {
        "mass": (29.8000001, 0.01),
        "tool0_home": ([0.33, 0.0, 0.573], 1e-4),
        "base_link_height": (0.17504, 1e-4),  # within the tolerance: kept as written
    }
    new, edits = rewrite_published(TEXT, "r.yaml", values)
    assert [(e.field, e.line, e.old, e.new) for e in edits] == [
        ("published.mass", 3, "29.3", "29.8"),
        ("published.tool0_home[2]", 4, "0.423", "0.573"),
    ]
    old_lines, new_lines = TEXT.splitlines(), new.splitlines()
    changed = [k for k, (a, b) in enumerate(zip(old_lines, new_lines, strict=True)) if a != b]
    assert changed == [2, 3]
    assert new_lines[2] == "  mass: 29.8                  # kg (kit page table)"
    assert new_lines[3] == "  tool0_home: [0.330, 0.0, 0.573]   # m"


def test_block_lists_and_agreeing_values():
    new, edits = rewrite_published(TEXT, "r.yaml", {"reach": ([0.5, 0.61], 1e-4)})
    assert [e.field for e in edits] == ["published.reach[1]"]
    assert "    - 0.61\n" in new and "    - 0.5\n" in new
    same, none = rewrite_published(TEXT, "r.yaml", {"mass": (29.30001, 0.01)})
    assert same == TEXT and none == []


def test_values_are_spelled_to_a_hundredth_of_their_tolerance():
    assert spelled(29.80000001, 0.01) == "29.8"
    assert spelled(0.57312345, 1e-4) == "0.573123"
    assert spelled(30, 0.01) == "30.0"
    assert spelled(-1e-9, 1e-4) == "0.0"


def test_an_installed_package_spec_is_never_rewritten(tmp_path):
    wheel = tmp_path / "site-packages" / "simkit" / "_data" / "robots"
    checkout = tmp_path / "repo" / "robots"
    for folder in (wheel, checkout):
        folder.mkdir(parents=True)
        (folder / "r.yaml").write_text(TEXT)
    assert installed_spec(wheel / "r.yaml", wheel)
    assert not installed_spec(checkout / "r.yaml", checkout)
    assert not installed_spec(tmp_path / "r.yaml", wheel)  # a copy the user named


def test_a_symlinked_spec_is_refused_before_any_work(tmp_path):
    real = tmp_path / "real.yaml"
    real.write_text((REPO / "tests" / "specs" / "planar_2r.yaml").read_text())
    link = tmp_path / "planar_2r.yaml"
    os.symlink(real, link)
    before = real.read_bytes()
    run = CliRunner().invoke(main, ["build", str(link), "--accept-published", "--no-cache"])
    assert run.exit_code == 2 and "a symbolic link" in run.output
    assert real.read_bytes() == before and link.is_symlink()


@pytest.mark.slow
def test_a_heavier_link_then_accept_published_builds_green(tmp_path):
    spec = tmp_path / "rosie_600.yaml"
    original = (REPO / "robots" / "rosie_600.yaml").read_text()
    old = "  - name: link_2\n    mass: 6.6\n"
    assert old in original
    spec.write_text(original.replace(old, "  - name: link_2\n    mass: 7.1\n"))
    (tmp_path / "keep.txt").write_text("not a spec")
    line = original.splitlines().index("published:") + 2  # mass is the block's first key
    with pytest.raises(CheckFailed) as info:
        build(str(spec), tmp_path / "out")
    assert (
        f"{spec}:{line}: published.mass: the spec publishes 29.3 kg, the model gives 29.8 kg"
        in str(info.value)
    )
    assert "--accept-published" in str(info.value)
    edited = spec.read_text()
    run = CliRunner().invoke(
        main, ["build", str(spec), "--accept-published", "--out", str(tmp_path / "out")]
    )
    assert run.exit_code == 0, run.output
    assert f"{spec}:{line}: published.mass: 29.3 -> 29.8" in run.output
    after = spec.read_text()
    assert after == edited.replace(
        "  mass: 29.3                  # kg", "  mass: 29.8                  # kg", 1
    )
    assert (tmp_path / "keep.txt").read_text() == "not a spec"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt", "out", "rosie_600.yaml"]
    passed = re.search(r"; (\d+)/(\d+) checks passed", run.output)
    assert passed is not None and passed[1] == passed[2], run.output
