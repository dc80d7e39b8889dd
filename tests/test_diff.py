"""`simkit diff`: semantic report of what changed between two kits."""

from __future__ import annotations

import json
import shutil
import zipfile

import numpy as np
import pytest
from click.testing import CliRunner

from simkit.cli import main
from simkit.diff import diff_kits
from simkit.diff_text import to_markdown
from simkit.kitio.stl import from_stl, to_stl


@pytest.fixture()
def copy(rosie_1000, tmp_path):
    """A private copy of the shared kit, to modify."""
    target = tmp_path / "new"
    shutil.copytree(rosie_1000.kit_dir, target)
    return target


def _edit_json(kit, change) -> None:
    path = kit / "robot.json"
    doc = json.loads(path.read_text())
    change(doc)
    path.write_text(json.dumps(doc, indent=2) + "\n")


def _key(c) -> tuple:
    return (c.kind, c.name, c.change, c.field)


def test_kit_against_itself_and_its_zip_is_equal(rosie_1000):
    runner = CliRunner()
    for other in (rosie_1000.kit_dir, rosie_1000.zip_path):
        result = runner.invoke(main, ["diff", str(rosie_1000.kit_dir), str(other)])
        assert result.exit_code == 0, result.output
        assert "No changes" in result.output
    args = ["diff", "--json", str(rosie_1000.zip_path), str(rosie_1000.kit_dir)]
    result = runner.invoke(main, args)
    doc = json.loads(result.output)
    assert result.exit_code == 0 and doc["equal"] and doc["changes"] == []


def test_one_limit_and_one_mass_change_report_exactly_those_two(rosie_1000, copy):
    def change(doc):
        doc["joints"][1]["upper"] = 2.0  # J2, rad
        doc["links"][2]["mass"] = 11.0  # link_2, kg

    _edit_json(copy, change)
    report = diff_kits(rosie_1000.kit_dir, copy)
    assert [_key(c) for c in report.changes] == [
        ("joint", "J2", "modified", "upper"),
        ("link", "link_2", "modified", "mass"),
    ]
    joint, link = report.changes
    assert (joint.new, joint.unit) == (2.0, "rad") and joint.old == pytest.approx(np.radians(135))
    assert (link.old, link.new, link.unit) == (10.4, 11.0, "kg")
    assert report.changed == ["robot.json"] and not report.added and not report.removed
    text = to_markdown(report)
    assert "| `J2` | upper | 2.35619 rad (135 deg) | 2 rad (114.59 deg) | -0.356194 rad" in text
    assert "| `link_2` | mass | 10.4 kg | 11 kg | +0.6 kg, 5.77 % |" in text
    result = CliRunner().invoke(main, ["diff", "--json", str(rosie_1000.kit_dir), str(copy)])
    assert result.exit_code == 1
    assert len(json.loads(result.output)["changes"]) == 2


def test_each_kind_of_change(rosie_1000, copy):
    def change(doc):
        j1, j3 = doc["joints"][0], doc["joints"][2]
        j1["max_velocity"] = 3.0
        j1["effort_peak"] = 300.0
        j3["lower"] = -2.0
        j3["drive_peak_torque_at_joint"] = 200.0
        doc["links"][1]["com"] = [0.0, 0.0, 0.06]
        doc["links"][1]["inertia"]["ixx"] = 0.05
        doc["links"].append(dict(doc["links"][-1], name="link_7"))
        doc["fixed_joints"] = []  # base_joint removed
        doc["payload"]["rated"] = 12.0

    _edit_json(copy, change)
    # link_4's visual mesh scaled by 1.1: volume x 1.331, bounding box x 1.1
    stl = copy / "meshes" / "visual" / "link_4.stl"
    mesh = from_stl(stl.read_bytes())
    stl.write_bytes(to_stl(mesh._replace(vertices=mesh.vertices * 1.1), "link_4"))
    # one more convex piece for link_1, and README removed
    pieces = sorted((copy / "meshes" / "collision").glob("link_1_*.stl"))
    shutil.copy(pieces[0], copy / "meshes" / "collision" / f"link_1_{len(pieces):02d}.stl")
    (copy / "README.md").unlink()

    report = diff_kits(rosie_1000.kit_dir, copy)
    keys = {_key(c) for c in report.changes}
    assert keys >= {
        ("joint", "J1", "modified", "max_velocity"),
        ("joint", "J1", "modified", "effort_peak"),
        ("joint", "J3", "modified", "lower"),
        ("joint", "J3", "modified", "drive_peak_torque_at_joint"),
        ("joint", "base_joint", "removed", ""),
        ("link", "link_1", "modified", "com"),
        ("link", "link_1", "modified", "inertia"),
        ("link", "link_7", "added", ""),
        ("mesh", "meshes/visual/link_4.stl", "modified", "volume"),
        ("mesh", "meshes/visual/link_4.stl", "modified", "bbox"),
        ("collision", "link_1", "modified", "pieces"),
        ("robot_json", "payload", "modified", "rated"),
    }
    extra = keys - {k for k in keys if k[0] != "mesh" and k[0] != "collision"}
    scaled = ("volume", "bbox", "displacement", "shape")  # scaled about the link origin
    assert extra <= {("mesh", "meshes/visual/link_4.stl", "modified", f) for f in scaled} | {
        ("collision", "link_1", "modified", "pieces")
    }
    by_key = {_key(c): c for c in report.changes}
    volume = by_key[("mesh", "meshes/visual/link_4.stl", "modified", "volume")]
    assert volume.new / volume.old == pytest.approx(1.331, rel=1e-5) and volume.unit == "m^3"
    box = by_key[("mesh", "meshes/visual/link_4.stl", "modified", "bbox")]
    assert np.allclose(np.array(box.new) / np.array(box.old), 1.1, rtol=1e-5)
    pieces_change = by_key[("collision", "link_1", "modified", "pieces")]
    assert pieces_change.new == pieces_change.old + 1
    assert report.added == [f"meshes/collision/link_1_{len(pieces):02d}.stl"]
    assert report.removed == ["README.md"]
    assert set(report.changed) == {"robot.json", "meshes/visual/link_4.stl"}
    text = to_markdown(report)
    for heading in ("## Joints", "## Links", "## Meshes", "## Collision pieces", "## Files"):
        assert heading in text
    assert "`link_7` added" in text and "`base_joint` removed" in text
    assert "(deg/s)" not in text and "deg/s)" in text  # speeds shown in rad/s and deg/s


def test_missing_kit_is_one_line_error(tmp_path):
    result = CliRunner().invoke(main, ["diff", str(tmp_path / "nope"), str(tmp_path)])
    assert result.exit_code == 2 and "no such kit" in result.output


def test_not_a_kit_is_one_line_error(rosie_1000, tmp_path):
    """A folder or zip without robot.json, a file that is not a zip, a kit with a broken
    robot.json or STL: one line, exit 2, no traceback (not "everything removed")."""
    plain = tmp_path / "plain"
    plain.mkdir()
    (plain / "notes.txt").write_text("not a kit")
    no_kit_zip = tmp_path / "plain.zip"
    with zipfile.ZipFile(no_kit_zip, "w") as archive:
        archive.writestr("plain/notes.txt", "not a kit")
    not_zip = tmp_path / "bad.zip"
    not_zip.write_bytes(b"PK\x03\x04 truncated")
    broken_json = tmp_path / "broken_json"
    shutil.copytree(rosie_1000.kit_dir, broken_json)
    (broken_json / "robot.json").write_text("{")
    broken_stl = tmp_path / "broken_stl"
    shutil.copytree(rosie_1000.kit_dir, broken_stl)
    (broken_stl / "meshes" / "visual" / "link_1.stl").write_bytes(b"solid x")
    runner = CliRunner()
    for other, message in (
        (plain, "not a kit"),
        (no_kit_zip, "not a kit"),
        (not_zip, "not a kit zip"),
        (broken_json, "not valid JSON"),
        (broken_stl, "not a binary STL"),
    ):
        arg_sets = [
            [str(rosie_1000.kit_dir), str(other)],
            ["--json", str(other), str(rosie_1000.kit_dir)],
        ]
        for args in arg_sets:
            result = runner.invoke(main, ["diff", *args])
            assert result.exit_code == 2, (other, result.output)
            assert result.output.count("\n") == 1 and message in result.output, result.output
            assert "Traceback" not in result.output


def test_zip_of_the_kit_contents_without_a_top_folder(rosie_1000, tmp_path):
    flat = tmp_path / "flat.zip"
    with zipfile.ZipFile(flat, "w") as archive:
        for path in sorted(rosie_1000.kit_dir.rglob("*")):
            if path.is_file():
                archive.write(path, path.relative_to(rosie_1000.kit_dir).as_posix())
    report = diff_kits(rosie_1000.zip_path, flat)
    assert report.equal, (report.added, report.removed, report.changed)
