"""geometry.connected (issue 38): at home each link's solid meets its parent's across their
joint; a joint moved without its solids fails the build in one line naming both links and the
gap; an imported robot's floating meshes are reported, never failed."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import trimesh

from simkit.check import CHECKS
from simkit.check.connected import CONNECTED_TOL, check_connected, joint_gaps
from simkit.check.kit import Kit
from simkit.errors import CheckFailed
from simkit.kitio.stl import to_stl

REPO = Path(__file__).resolve().parents[1]


def _kit(root: Path, joint_z: float, imported: bool = False) -> Kit:
    """A two-link kit: a 0.1 m cube on the base, another on a joint at `joint_z` (the cubes
    touch at 0.1 m)."""
    (root / "meshes" / "visual").mkdir(parents=True)
    for name in ("base", "arm"):
        cube = trimesh.creation.box((0.1, 0.1, 0.1))
        cube.apply_translation((0, 0, 0.05))
        (root / "meshes" / "visual" / f"{name}.stl").write_bytes(to_stl(cube, name))
    doc = {
        "name": "mini",
        "base_frame": "base",
        "joints": [
            {
                "name": "j1",
                "type": "revolute",
                "parent": "base",
                "child": "arm",
                "origin_xyz": [0, 0, joint_z],
                "origin_rpy": [0, 0, 0],
                "axis": [0, 0, 1],
            }
        ],
        "fixed_joints": [],
        "links": [
            {"name": n, "mesh": {"visual": f"meshes/visual/{n}.stl"}} for n in ("base", "arm")
        ],
        "home": [0.5],
        "frames": {},
    }
    if imported:
        doc["source"] = {"file": "mini.source.urdf", "sha256": "0" * 64}
    (root / "robot.json").write_text(json.dumps(doc))
    return Kit.open(root)


def test_touching_solids_pass(tmp_path):
    found = check_connected(_kit(tmp_path, 0.1))
    assert [f.ok for f in found] == [True]
    assert "1 joints: each link's solid meets its parent's" in found[0].detail
    assert found[0].check == "geometry.connected"
    assert "connected" in CHECKS


def test_a_moved_joint_fails_naming_both_links_and_the_gap(tmp_path):
    found = check_connected(_kit(tmp_path, 0.16))
    assert len(found) == 1 and not found[0].ok
    line = found[0].line()
    assert line.startswith(
        "FAIL geometry.connected: at home, arm's solid does not meet base's across j1: "
        "a gap of 0.06 m"
    )
    assert line.endswith(f"expected 0, got 0.06 (tolerance {CONNECTED_TOL:g} m)")
    (_, parent, child, gap) = joint_gaps(Kit.open(tmp_path))[0]
    assert (parent, child) == ("base", "arm") and gap == pytest.approx(0.06, abs=1e-6)


def test_an_imported_robot_only_reports(tmp_path):
    found = check_connected(_kit(tmp_path, 0.16, imported=True))
    assert [f.ok for f in found] == [True]
    assert found[0].detail.startswith("imported robot, reported only: 1 of 1 links may float")
    assert "arm from base (0.06 m)" in found[0].detail


def test_the_exact_gap_is_zero_for_overlapping_solids(tmp_path):
    gaps = joint_gaps(_kit(tmp_path, 0.05))
    assert gaps == [("j1", "base", "arm", 0.0)]


@pytest.mark.slow
def test_a_longer_upper_arm_fails_the_build_in_one_line(spec_variant):
    """The issue's edit: rosie_600's upper arm 150 mm longer (J3's origin), solids left."""
    old = "    xyz: [0, 0, 0.270]        # upper arm"
    with pytest.raises(CheckFailed) as info:
        spec_variant(REPO / "robots" / "rosie_600.yaml", old, old.replace("0.270", "0.420"))
    lines = [line for line in str(info.value).splitlines() if "geometry.connected" in line]
    assert len(lines) == 1, str(info.value)
    gap = re.search(r"link_3's solid does not meet link_2's across J3: a gap of (\S+) m", lines[0])
    assert gap is not None and float(gap[1]) > CONNECTED_TOL, lines[0]
