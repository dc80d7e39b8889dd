"""SDFormat import (importer/formats/sdf): simkit's own reader of the frame semantics, tested
against Drake's SDFormat parser (libsdformat inside pydrake, a test-only dependency) on small
files written for each construct: `relative_to` poses and `<frame>`s, a joint's default frame
(its child link), `expressed_in` axes, nested and merged `<include>`s through `model://`; and
the one-line refusals. The comparison is the source proof's (check/source/sdf/): the source
model the reader gives is written as a URDF and read by Drake beside the SDF."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from lxml import etree

from simkit.errors import SpecError
from simkit.importer import formats
from simkit.importer.diagnostics import Policy, Report
from simkit.importer.formats.urdf.document import document
from simkit.importer.translate import ball_joints, loops

pytest.importorskip("pydrake")
from simkit.check.source import sdf as proof
from simkit.check.source.shared import Allowed

FILES = Path(__file__).resolve().parent / "sdf_files"


def _read(path: Path):
    return formats.load(path, report=Report(Policy()))


def _findings(path: Path, tmp_path: Path, tamper=None) -> list:
    """The proof's findings: Drake's reading of the SDF against the reader's source model
    (written as URDF, a ball joint as the three revolute ones the translation makes of it)."""
    read = _read(path)
    ball_joints.expand(read)  # on the source model, which is what the translation reads
    tree = document(read.robot)
    if tamper:
        tamper(tree)
    urdf = tmp_path / "tree.urdf"
    urdf.write_bytes(etree.tostring(tree))
    root = path.parent.parent if (path.parent / "model.config").is_file() else path.parent
    laid = tmp_path / "laid"  # as the proof lays the source out: model folders named by file
    shutil.copytree(root, laid)
    for copy in laid.rglob("*.sdf"):
        proof.model_folders(copy, laid)
    path = laid / path.relative_to(root)
    source = proof.Plant(path, laid)
    return proof.Compare(source, proof.Plant(urdf, tmp_path), Allowed()).findings()


def test_frames_relative_to_and_default_joint_frame(tmp_path):
    """relative_to chains through a <frame>, a joint pose relative to its child link, an
    axis expressed in the model frame and one in the joint frame: Drake agrees."""
    robot = _read(FILES / "frames.sdf").robot
    mount = next(j for j in robot.joints if j.child == "mount")  # a <frame>: a kit frame
    assert mount.type == "fixed" and mount.parent == "base"
    found = _findings(FILES / "frames.sdf", tmp_path)
    assert [f.check for f in found] == ["source.joints", "source.links", "source.fk"]
    assert all(f.ok for f in found), found


def test_scopes_frames_as_joint_ends_and_degrees(tmp_path):
    """A nested model placed relative to a frame, a frame attached to a nested model, a joint
    from a frame to a nested link, an axis expressed in a frame, a pose in degrees."""
    found = _findings(FILES / "scopes.sdf", tmp_path)
    assert all(f.ok for f in found), found


def test_universal_joint_is_two_revolute_joints(tmp_path):
    """A universal joint: `u_1` about <axis>, `u` about <axis2>, the child's frame turned as
    Drake turns it; Drake agrees (FK at 100 configurations, masses)."""
    read = _read(FILES / "universal.sdf")
    kinds = {j.name: j.type for j in read.robot.joints}
    assert kinds == {"u_1": "revolute", "u": "revolute"}
    found = _findings(FILES / "universal.sdf", tmp_path)
    assert all(f.ok for f in found), found


def test_proof_fails_when_the_joint_frame_is_read_as_urdf_does(tmp_path):
    """The same file, the joint's pose read relative to the parent (URDF's rule): FK fails."""

    def urdf_rule(tree):
        origin = tree.find("joint[@name='shoulder']/origin")
        origin.set("xyz", "0 0.05 -0.1")

    found = _findings(FILES / "frames.sdf", tmp_path, urdf_rule)
    assert any(f.check == "source.fk" and not f.ok for f in found)


def test_proof_fails_when_a_kit_frame_is_misplaced(tmp_path):
    """The kit frame of <frame name="mount"> moved 1 mm: the proof's FK names it."""

    def moved(tree):
        origin = tree.xpath("joint[child/@link='mount']/origin")[0]
        x, y, z = (float(v) for v in origin.get("xyz").split())
        origin.set("xyz", f"{x + 0.001} {y} {z}")

    found = _findings(FILES / "frames.sdf", tmp_path, moved)
    assert [f.detail for f in found if not f.ok and "'mount'" in f.detail], found


def test_nested_and_merged_include_through_model_uri(tmp_path):
    """model://finger included twice: nested (`left::knuckle`) and merged (`knuckle`), a
    joint axis expressed in a nested link's frame: Drake agrees; the names are scoped."""
    path = FILES / "models" / "robot" / "model.sdf"
    robot = _read(path).robot
    names = {link.name for link in robot.links}
    assert names == {"palm", "left::knuckle", "left::pad", "knuckle", "pad", "left::tip", "tip"}
    frames = {j.child: j.parent for j in robot.joints}
    assert frames["tip"] == "knuckle" and frames["left::tip"] == "left::knuckle"  # model frame
    found = _findings(path, tmp_path)
    assert all(f.ok for f in found), found


def test_world_model_pose_world_joint_ball_and_old_axis_frame(tmp_path):
    """A world file: the one robot beside static scenery (dropped, one line), placed by its
    model pose and mounted on the world by a revolute joint whose SDFormat 1.6 axis is in
    the parent model frame; a ball joint: Drake agrees; the base is fixed."""
    path = FILES / "world.sdf"
    report = Report(Policy())
    read = formats.load(path, report=report)
    assert read.base is not None and read.base[0] is False
    assert "swivel" in read.base[1]
    assert [line for line in report.lines if "scenery" in line and "ground" in line]
    found = _findings(path, tmp_path)
    assert all(f.ok for f in found), found


def test_model_folder_is_read_through_model_config(tmp_path):
    """A Gazebo model folder given as the robot: the SDF its model.config names."""
    picked = formats.pick(FILES / "models" / "robot")
    assert picked.format.name == "sdf"
    assert picked.path == (FILES / "models" / "robot" / "model.sdf").resolve()


def _one_line(tmp_path: Path, body: str, version: str = "1.9") -> str:
    path = tmp_path / "m.sdf"
    path.write_text(f'<?xml version="1.0"?>\n<sdf version="{version}">\n{body}\n</sdf>\n')
    with pytest.raises(SpecError) as caught:
        _read(path)
    text = str(caught.value)
    assert "\n" not in text and "m.sdf" in text
    return text


LINKS = '<link name="a"/><link name="b"/>'


def test_refusals_are_one_line(tmp_path):
    joint = '<joint name="u" type="revolute2"><parent>a</parent><child>b</child></joint>'
    assert "revolute2 joint" in _one_line(tmp_path, f'<model name="m">{LINKS}{joint}</model>')
    assert "1.4 to 1.11" in _one_line(tmp_path, '<model name="m"><link name="a"/></model>', "2.0")
    fixed = '<joint name="j" type="fixed"><parent>a</parent><child>b</child></joint>'
    robot = f'<model name="{{}}">{LINKS}{fixed}</model>'
    world = f"<world name='w'>{robot.format('r1')}{robot.format('r2')}</world>"
    assert "several robots" in _one_line(tmp_path, world)
    frame = '<frame name="{}" attached_to="{}"><pose relative_to="{}"/></frame>'
    cycle = (
        f'<model name="m">{frame.format("f", "g", "g")}{frame.format("g", "f", "f")}'
        '<link name="a"><pose relative_to="f"/></link></model>'
    )
    assert "cycle" in _one_line(tmp_path, cycle)
    free = '<model name="m"><link name="a"/><link name="b"/></model>'
    assert "2 links hang from no joint" in _one_line(tmp_path, free)


def test_extensions_are_dropped_one_line_each(tmp_path):
    path = tmp_path / "m.sdf"
    path.write_text(
        '<?xml version="1.0"?>\n<sdf version="1.9" xmlns:drake="http://drake.mit.edu">\n'
        '<model name="m"><link name="a"><sensor name="s" type="imu"/></link>'
        '<plugin name="p" filename="libx.so"/><drake:joint name="d"/><gz:undeclared/>'
        "</model></sdf>\n"
    )
    report = Report(Policy())
    formats.load(path, report=report)
    dropped = [line for line in report.lines if "not carried" in line]
    assert len(dropped) == 4, report.lines
    assert any("drake:joint[d]" in line for line in dropped), dropped


@pytest.mark.slow
def test_seed_kit_sdf_round_trip(kit_factory, tmp_path):
    """A seed kit's own SDF imports to a kit whose URDF the source proof (Drake) finds
    equal to the SDF's robot (the build runs that proof), and equal to the seed kit's own
    URDF: masses, CoMs, inertias, FK at 100 seeds, joint types and limits."""
    from simkit.importer import import_robot
    from simkit.pipeline import build

    kit = kit_factory("ecn_2r").kit_dir
    copy = tmp_path / kit.name
    shutil.copytree(kit, copy)
    sdf = next((copy / "sdf").glob("*.sdf"))
    done = import_robot(sdf, tmp_path / "spec", name="ecn_2r_back")
    result = build(str(done.spec_path), tmp_path / "kits", step=False, remember=False)
    proved = [f for f in result.findings if f.check.startswith("source.")]
    assert {f.check for f in proved} >= {"source.joints", "source.links", "source.fk"}
    assert all(f.ok for f in proved), [f for f in proved if not f.ok]
    back = result.kit_dir
    allowed = Allowed.of(json.loads((back / "robot.json").read_text()))
    original = proof.Plant(next((copy / "urdf").glob("*.urdf")), copy.parent)
    found = proof.Compare(
        original, proof.Plant(next((back / "urdf").glob("*.urdf")), back.parent), allowed
    )
    assert all(f.ok for f in found.findings()), found.findings()


def test_proof_without_drake_fails_naming_the_install(monkeypatch, tmp_path):
    """Without pydrake the SDFormat proof is one failing finding naming `pip install drake`
    (the user asked for the proof; an unproved kit must not pass)."""
    monkeypatch.setitem(__import__("sys").modules, "pydrake", None)  # import raises
    found = proof.compare(None, FILES / "frames.sdf")
    assert len(found) == 1 and not found[0].ok and "pip install drake" in found[0].detail


def test_a_static_model_has_a_fixed_base(tmp_path):
    path = tmp_path / "s.sdf"
    path.write_text(
        f'<?xml version="1.0"?>\n<sdf version="1.9"><model name="m"><static>true</static>{LINKS}'
        '<joint name="j" type="revolute"><parent>a</parent><child>b</child>'
        "<axis><xyz>0 0 1</xyz></axis></joint></model></sdf>\n"
    )
    read = _read(path)
    assert read.base == (False, "fixed base: the model is <static>; --floating-base frees it")


def test_closed_loop_keeps_the_first_parent_joint(tmp_path):
    """A link with two parent joints: the tree keeps the first, the second is left out with
    one report line (translate/loops.py second_parents, on the source model as for a URDF)."""
    path = tmp_path / "loop.sdf"
    path.write_text(
        '<?xml version="1.0"?>\n<sdf version="1.9"><model name="m">'
        '<link name="a"/><link name="b"/><link name="c"/>'
        '<joint name="ab" type="revolute"><parent>a</parent><child>b</child>'
        "<axis><xyz>0 0 1</xyz></axis></joint>"
        '<joint name="ac" type="revolute"><parent>a</parent><child>c</child>'
        "<axis><xyz>0 0 1</xyz></axis></joint>"
        '<joint name="bc" type="fixed"><parent>b</parent><child>c</child></joint>'
        "</model></sdf>\n"
    )
    report = Report(Policy())
    read = formats.load(path, report=report)
    loops.second_parents(read, report)
    assert [j.name for j in read.robot.joints] == ["ab", "ac"]
    assert [j.name for j in read.closures] == ["bc"]
    assert any("closed loop" in line and "bc" in line for line in report.lines)


def test_a_mesh_through_model_uri_is_imported(tmp_path):
    """A mesh named `model://NAME/...` in a Gazebo model folder is read into the kit's spec."""
    import trimesh

    from simkit.importer import import_robot

    folder = tmp_path / "robot"
    (folder / "meshes").mkdir(parents=True)
    trimesh.creation.box((0.1, 0.2, 0.3)).export(folder / "meshes" / "box.stl")
    (folder / "model.config").write_text('<model><sdf version="1.9">r.sdf</sdf></model>')
    mesh = "<geometry><mesh><uri>model://robot/meshes/box.stl</uri></mesh></geometry>"
    (folder / "r.sdf").write_text(
        '<?xml version="1.0"?>\n<sdf version="1.9"><model name="r">'
        f'<link name="a"><visual name="v">{mesh}</visual></link><link name="b"/>'
        '<joint name="j" type="revolute"><parent>a</parent><child>b</child>'
        "<axis><xyz>0 0 1</xyz><limit><lower>-1</lower><upper>1</upper></limit></axis></joint>"
        "</model></sdf>\n"
    )
    done = import_robot(folder, tmp_path / "out")
    assert done.meshes == 1 and done.spec_path.name == "r.yaml"
    assert (tmp_path / "out" / "r.source.sdf").read_bytes() == (folder / "r.sdf").read_bytes()
