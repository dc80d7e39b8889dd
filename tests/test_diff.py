"""`simkit diff`: semantic report of what changed between two kits."""

from __future__ import annotations

import json
import shutil
import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from simkit.cli import main
from simkit.diff import diff_kits
from simkit.diff.markdown import to_markdown
from simkit.kitio.obj import read_mesh, to_obj
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
    assert "| `J2` | upper | 2.356194 rad (135 deg) | 2 rad (114.5916 deg) | -0.356194 rad" in text
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
    pieces = sorted((copy / "meshes" / "collision").glob("link_1_*.obj"))
    shutil.copy(pieces[0], copy / "meshes" / "collision" / f"link_1_{len(pieces):02d}.obj")
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
    scaled = ("scale", "volume", "bbox", "displacement")  # scaled about the link origin
    assert extra <= {("mesh", "meshes/visual/link_4.stl", "modified", f) for f in scaled} | {
        ("collision", "link_1", "modified", "pieces")
    }
    by_key = {_key(c): c for c in report.changes}
    volume = by_key[("mesh", "meshes/visual/link_4.stl", "modified", "volume")]
    assert volume.new / volume.old == pytest.approx(1.331, rel=1e-5) and volume.unit == "m^3"
    box = by_key[("mesh", "meshes/visual/link_4.stl", "modified", "bbox")]
    assert np.allclose(box.new, np.multiply(box.old, 1.1), atol=2e-6)  # bounds, at 1e-6 m
    scale = by_key[("mesh", "meshes/visual/link_4.stl", "modified", "scale")]
    assert scale.new == pytest.approx(1.1, abs=1e-5)
    pieces_change = by_key[("collision", "link_1", "modified", "pieces")]
    assert pieces_change.new == pieces_change.old + 1
    assert report.added == [f"meshes/collision/link_1_{len(pieces):02d}.obj"]
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


# --- issue 23: tolerances, placement, --markdown, complete tables; issue 24: hostile values ---

ECN_SPEC = Path(__file__).resolve().parents[1] / "robots" / "ecn_2r.yaml"
ARM_BOX = "size: [0.28, 0.08, 0.05], xyz: [0.14, 0, 0.175]"


def test_tolerances_are_the_checks():
    """One rule per quantity: diff.tolerance's constants are the checks' own tolerances."""
    from simkit.check import geometry, mujoco, urdf
    from simkit.diff.tolerance import ANGLE_RAD, LENGTH_M, PARAM_SI

    assert LENGTH_M == urdf.TOL == mujoco.PARAM_TOL == geometry.CONVEX_TOL
    assert ANGLE_RAD == urdf.TOL and PARAM_SI == mujoco.PARAM_TOL


def test_round_off_below_the_tolerances_is_no_change():
    """Numbers within the tolerance of their quantity are equal; beyond it they are not."""
    from simkit.diff.tolerance import close, leaf_changes, text_close

    assert close(0.28, 0.280000001, 1e-6) and not close(0.28, 0.281, 1e-6)
    assert close(float("nan"), float("nan"), 1e-6) and not close(1.0, float("nan"), 1e-6)
    assert list(leaf_changes({"a": [1.0, 2.0]}, {"a": [1.0 + 1e-9, 2.5]}, 1e-6)) == [
        ("a[1]", 2.0, 2.5)
    ]
    assert text_close(b'<origin xyz="0.14 0 0.175"/>', b'<origin xyz="0.1400000005 0 0.175"/>')
    assert not text_close(b'<origin xyz="0.14 0 0.175"/>', b'<origin xyz="0.15 0 0.175"/>')
    assert not text_close(b"<link name='a'/>", b"<link name='b'/>")


def test_a_length_changed_by_1e_9_m_prints_no_change(spec_variant):
    """The arm box 1e-9 m longer: files differ by round-off (and a new triangulation of the
    same solid), the diff reports nothing and exits 0. Both built from a spec of one name,
    which the files' headers name."""
    old = spec_variant(ECN_SPEC, ARM_BOX, ARM_BOX)
    new = spec_variant(ECN_SPEC, ARM_BOX, ARM_BOX.replace("0.28,", "0.280000001,"))
    report = diff_kits(old.kit_dir, new.kit_dir)
    assert report.equal and not report.identical, report.changes
    assert report.changes == [] and report.changed == [] and report.round_off
    assert report.metadata == ["provenance.spec_sha256"]
    result = CliRunner().invoke(main, ["diff", str(old.kit_dir), str(new.kit_dir)])
    assert result.exit_code == 0, result.output
    assert "No changes beyond the checks' tolerances" in result.output
    assert "m^3" not in result.output and "| " not in result.output


def test_a_primitive_moved_50_mm_is_reported_with_its_displacement(kit_factory, spec_variant):
    old = kit_factory("ecn_2r")
    new = spec_variant(ECN_SPEC, ARM_BOX, ARM_BOX.replace("0.14, 0,", "0.14, 0.05,"))
    report = diff_kits(old.kit_dir, new.kit_dir)
    moved = [
        c
        for c in report.changes
        if c.kind == "mesh" and c.name.startswith("meshes/collision/") and c.field == "displacement"
    ]
    assert len(moved) == 1, report.changes
    step = np.subtract(moved[0].new, moved[0].old)
    assert np.allclose(step, [0, 0.05, 0], atol=1e-3), step
    assert not report.equal


def _edit_mesh(path, change) -> None:
    """Edit a kit mesh's vertices: a visual STL or a collision OBJ, rewritten as such."""
    mesh = read_mesh(path.name, path.read_bytes())
    write = to_obj if path.suffix == ".obj" else to_stl
    path.write_bytes(write(mesh._replace(vertices=change(mesh.vertices)), path.stem))


def test_collision_pieces_moved_and_turned_are_reported(rosie_1000, copy):
    """A piece moved 50 mm and another turned 10 deg about its centre (same size: the old
    comparison of bounding-box sizes saw neither the move nor, for a round piece, the turn)."""
    pieces = sorted((copy / "meshes" / "collision").glob("*.obj"))
    _edit_mesh(pieces[0], lambda v: np.add(v, [0.05, 0.0, 0.0]))
    turn = np.radians(10)
    rot = np.array([[1, 0, 0], [0, np.cos(turn), -np.sin(turn)], [0, np.sin(turn), np.cos(turn)]])
    _edit_mesh(pieces[1], lambda v: (v - v.mean(axis=0)) @ rot.T + v.mean(axis=0))
    report = diff_kits(rosie_1000.kit_dir, copy)
    by_key = {(c.name, c.field): c for c in report.changes}
    first, second = (p.relative_to(copy).as_posix() for p in pieces[:2])
    moved = by_key[(first, "displacement")]
    assert np.allclose(np.subtract(moved.new, moved.old), [0.05, 0, 0], atol=1e-3)
    assert np.degrees(by_key[(second, "rotation")].new) == pytest.approx(10, abs=0.01)
    assert (first, "rotation") not in by_key and (first, "shape") not in by_key
    text = to_markdown(report)
    assert "moved (0.05, 0, 0) m, 0.05 m" in text and "turned 10 deg" in text


def test_markdown_summary_is_short_and_points_to_the_html(rosie_1000, copy, tmp_path):
    """Many changes: --markdown writes the table first, at most 60 lines, then the pointer;
    stdout is the full report, as without the option; a second run appends."""

    def change(doc):
        for joint in doc["joints"]:
            for key in ("max_velocity", "effort_peak", "damping", "armature", "upper"):
                joint[key] = (joint[key] or 0.0) * 1.1 + 0.01
        for link in doc["links"]:
            link["mass"] *= 1.1
            link["com"] = [v + 0.01 for v in link["com"]]
            link["inertia"]["ixx"] *= 1.1

    _edit_json(copy, change)
    summary = tmp_path / "summary.md"
    args = ["diff", str(rosie_1000.kit_dir), str(copy), "--markdown", str(summary)]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 1, result.output
    assert result.output == to_markdown(diff_kits(rosie_1000.kit_dir, copy))
    lines = summary.read_text().splitlines()
    assert len(lines) <= 60, len(lines)
    assert lines[2].startswith("| kind | name | field | old | new | change |")
    assert "more" in "\n".join(lines) and lines[-1].startswith("Full report")
    CliRunner().invoke(main, args)
    assert summary.read_text().count("### simkit diff") == 2


def _table_columns(page: str) -> list[list[list[str]]]:
    """Each <table> of an HTML page as rows of cell texts (header row first)."""
    from html.parser import HTMLParser

    tables: list = []
    inside = [False]

    class Cells(HTMLParser):
        def handle_starttag(self, tag, attrs):
            if tag == "table":
                tables.append([])
            elif tag == "tr":
                tables[-1].append([])
            elif tag in ("td", "th"):
                tables[-1][-1].append("")
                inside[0] = True

        def handle_endtag(self, tag):
            inside[0] = inside[0] and tag not in ("td", "th")

        def handle_data(self, data):
            if inside[0]:
                tables[-1][-1][-1] += data.strip()

    Cells().feed(page)
    return tables


def test_html_tables_have_no_empty_columns(rosie_1000, copy):
    from simkit.review.diff_html import to_html

    def change(doc):
        doc["payload"]["rated"] = 12.0
        doc["links"].append(dict(doc["links"][-1], name="link_7"))
        doc["fixed_joints"] = []

    _edit_json(copy, change)
    report = diff_kits(rosie_1000.kit_dir, copy)
    tables = _table_columns(to_html(report, []))
    changes = [t for t in tables if t and t[0] and t[0][0] == "name"]
    assert len(changes) >= 3
    for table in changes:
        for column in range(len(table[0])):
            assert all(row[column] for row in table[1:]), (table[0][column], table)
    rated = next(r for t in changes for r in t[1:] if r[1] == "rated")
    assert rated == ["payload", "rated", "10", "12", "+2, 20 %"]


@pytest.mark.slow
def test_check_accepts_a_zip(rosie_1000):
    """Every check of the folder, the zip's own (its entries against the kit) included."""
    result = CliRunner().invoke(main, ["check", "-v", str(rosie_1000.zip_path)])
    assert result.exit_code == 0, result.output
    assert result.output.strip().endswith(f"{len(rosie_1000.findings)} passed, 0 failed")
    assert "ok   generated.zip" in result.output


def test_check_refuses_a_hostile_zip_in_one_line(rosie_1000, tmp_path):
    """A file and a folder of one name, a path leaving the kit: one line, nothing written."""
    doc = (rosie_1000.kit_dir / "robot.json").read_bytes()
    clash = tmp_path / "clash.zip"
    with zipfile.ZipFile(clash, "w") as archive:
        archive.writestr("kit/robot.json", doc)
        archive.writestr("kit/meshes", b"a file")
        archive.writestr("kit/meshes/a.stl", b"a file in a folder of the same name")
    leaving = tmp_path / "leaving.zip"
    with zipfile.ZipFile(leaving, "w") as archive:
        archive.writestr("kit/robot.json", doc)
        archive.writestr("kit/../../evil.txt", b"x")
    escape = f"simkit_escape_{tmp_path.name}"
    named = tmp_path / "named.zip"
    with zipfile.ZipFile(named, "w") as archive:
        doc = {"name": f"../{escape}", "joints": [], "fixed_joints": [], "links": []}
        archive.writestr("kit/robot.json", json.dumps(doc))
    result = CliRunner().invoke(main, ["check", str(named)])
    assert "Traceback" not in result.output and result.exit_code in (2, 3), result.output
    assert not list(Path(tempfile.gettempdir()).glob(f"{escape}*"))
    for path, message in ((clash, "cannot be extracted"), (leaving, "leaves the kit")):
        result = CliRunner().invoke(main, ["check", str(path)])
        assert result.exit_code == 2, result.output
        assert result.output.count("\n") == 1 and message in result.output, result.output
    assert not (tmp_path.parent / "evil.txt").exists()


def _hostile_json(kit) -> None:
    def change(doc):
        doc["links"][1]["mass"] = float("nan")
        doc["joints"][0]["upper"] = 1e308
        doc["links"][1]["com"][0] = -1e308
        doc["payload"]["rated"] = float("inf")

    _edit_json(kit, change)


def _strict_json(text: str) -> dict:
    def refuse(name):
        raise ValueError(f"{name} is not JSON")

    return json.loads(text, parse_constant=refuse)


def test_nan_and_1e308_in_robot_json_are_reported(rosie_1000, copy):
    from simkit.review.diff_html import to_html

    _hostile_json(copy)
    runner = CliRunner()
    result = runner.invoke(main, ["diff", str(rosie_1000.kit_dir), str(copy)])
    assert result.exit_code == 1 and "Traceback" not in result.output, result.output
    assert "| `link_1` | mass | 7.2 kg | NaN kg | changed |" in result.output
    assert "1e+308 rad" in result.output
    result = runner.invoke(main, ["diff", "--json", str(rosie_1000.kit_dir), str(copy)])
    doc = _strict_json(result.output)
    mass = next(c for c in doc["changes"] if c["field"] == "mass")
    assert mass["new"] == "NaN"
    page = to_html(diff_kits(rosie_1000.kit_dir, copy), [])
    assert "NaN kg" in page and "inf" in page


def test_junk_step_file_is_reported_not_raised(rosie_1000, copy, tmp_path):
    step = next((copy / "step").glob("*.step"))
    step.write_bytes(b"ISO-10303-21;\nthis is not STEP\n")
    from simkit.review.diff_html import to_html

    runner = CliRunner()
    for args in ([], ["--json"], ["--markdown", str(tmp_path / "s.md")]):
        result = runner.invoke(main, ["diff", *args, str(rosie_1000.kit_dir), str(copy)])
        assert result.exit_code == 1 and "Traceback" not in result.output, result.output
        assert "unreadable" in result.output
    doc = _strict_json(runner.invoke(main, ["diff", "--json", str(copy), str(copy)]).output)
    assert doc["equal"]
    report = diff_kits(rosie_1000.kit_dir, copy)
    assert "unreadable" in to_html(report, [])


def test_unwritable_outputs_are_one_line(rosie_1000, tmp_path):
    """--html and render --out under a path that is a file: one line naming it, nothing else
    written (checked before anything renders)."""
    blocker = tmp_path / "a_file"
    blocker.write_text("in the way")
    runner = CliRunner()
    kit = str(rosie_1000.kit_dir)
    for args in (
        ["diff", kit, kit, "--html", str(blocker / "report.html")],
        ["render", kit, "--out", str(blocker / "pngs")],
        ["diff", kit, kit, "--markdown", str(blocker / "summary.md")],
    ):
        result = runner.invoke(main, args)
        assert result.exit_code == 2, result.output
        assert result.output.count("\n") == 1 and str(blocker) in result.output, result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


def test_a_mesh_with_nan_vertices_is_reported(rosie_1000, copy):
    piece = sorted((copy / "meshes" / "collision").glob("*.obj"))[0]
    # a hand-edited (or corrupted) OBJ: the first vertex's x is `nan`
    text = piece.read_text().splitlines()
    first = next(i for i, line in enumerate(text) if line.startswith("v "))
    text[first] = "v nan " + " ".join(text[first].split()[2:])
    piece.write_text("\n".join(text) + "\n")
    report = diff_kits(rosie_1000.kit_dir, copy)
    change = next(c for c in report.changes if c.name.endswith(piece.name))
    assert (change.field, change.old, change.new) == ("vertices", "finite", "non-finite")


def test_any_other_joint_or_link_value_is_reported(rosie_1000, copy):
    """A joint's drive or a link's estimate list is no listed field, but a change all the
    same; the `*_deg` twins of a changed angle are not reported twice."""

    def change(doc):
        doc["joints"][0]["drive"]["motor_peak_torque"] = 4.0
        doc["joints"][0]["lower"] = -4.0
        doc["joints"][0]["lower_deg"] = -229.18
        doc["links"][1]["estimated"] = ["mass"]

    _edit_json(copy, change)
    report = diff_kits(rosie_1000.kit_dir, copy)
    assert sorted(_key(c) for c in report.changes) == [
        ("joint", "J1", "modified", "drive.motor_peak_torque"),
        ("joint", "J1", "modified", "lower"),
        ("link", "link_1", "modified", "estimated"),
    ]
    assert report.changed == ["robot.json"] and not report.equal
