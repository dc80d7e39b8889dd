"""`simkit import` (issue 15): URDF/xacro to a spec, gaps reported, errors on one line."""

from __future__ import annotations

import math
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner

import corpus_pick
from simkit.cli import main
from simkit.errors import SpecError
from simkit.importer import import_robot
from simkit.spec.validate import load_spec

URDF = Path(__file__).resolve().parent / "specs" / "urdf"
ARM = URDF / "pkg_demo" / "urdf" / "arm.urdf"


def test_arm_keeps_the_urdf_numbers(tmp_path):
    done = import_robot(ARM, tmp_path)
    spec, _doc = load_spec(done.spec_path)
    assert spec.root == "base_footprint"
    joints = {j.name: j for j in spec.joints}
    assert [j.type for j in spec.joints] == [
        "fixed",
        "revolute",
        "prismatic",
        "continuous",
        "continuous",
    ]
    follow = spec.joints[-1]
    assert follow.name == "spin_follow" and not follow.actuated
    assert (follow.mimic.joint, follow.mimic.multiplier, follow.mimic.offset) == ("spin", -1, 0.1)
    assert spec.poses["home"][-1] == 0.1  # the follower's home follows its leader's
    turn = joints["turn"]
    assert (turn.lower, turn.upper, turn.effort_peak, turn.max_velocity) == (-2.5, 2.5, 30, 2.0)
    assert (turn.damping, turn.friction, turn.rpy, turn.xyz) == (
        0.5,
        0.1,
        (0, 0, 0.1),
        (0, 0, 0.02),
    )
    assert joints["spin"].axis == (0, 1, 0) and joints["slide"].axis == (1, 0, 0)
    links = {link.name: link for link in spec.links}
    assert links["base_link"].mass == 2.0 and links["base_link"].com == (0, 0, 0.02)
    assert links["base_link"].collision == "primitives"
    # the bracket's inertial is rotated by its origin rpy into link axes: trace is kept
    i = links["bracket"].inertia
    assert math.isclose(i.ixx + i.iyy + i.izz, 0.0075, rel_tol=1e-12) and i.ixz != 0
    assert links["bracket"].solid[0].file == "meshes/bracket.stl"
    # the URDF's own collision mesh is kept as the link's piece (no CoACD)
    assert links["bracket"].collision == "given"
    assert links["bracket"].collision_shapes[0].file == "meshes/bracket.stl"
    assert links["wheel"].collision == "primitives" and not links["wheel"].collision_primitives
    assert (tmp_path / "meshes" / "bracket.stl").is_file()
    assert [p.shape for p in links["slider"].solid] == ["cylinder", "sphere"]
    # tool0: massless, no geometry, on a fixed joint -> a frame
    assert [(f.name, f.parent) for f in spec.frames] == [("tool0", "wheel")]
    assert spec.tool_frame == "tool0"
    colours = {m.name: m.rgba for m in spec.materials}
    assert colours[links["base_link"].material] == (0.1, 0.2, 0.8, 1.0)
    assert colours[links["bracket"].material] == (0.8, 0.1, 0.1, 1.0)


def test_gaps_are_estimated_and_reported(tmp_path):
    done = import_robot(ARM, tmp_path)
    spec, _doc = load_spec(done.spec_path)
    slide = next(j for j in spec.joints if j.name == "slide")
    assert set(slide.estimated) == {"max_velocity", "effort_peak", "armature"}
    slider = next(link for link in spec.links if link.name == "slider")
    assert slider.inertia_decision is not None and slider.inertia_decision.action == "balance"
    assert "triangle inequality" in slider.inertia_decision.reason
    text = "\n".join(done.lines)
    assert "transmission[turn_trans]" not in text  # kept (urdf_blocks), so not reported
    assert "gazebo: not imported: names 'no_such_link'" in text
    assert "arm.urdf:53: limit: estimated: no effort limit" in text
    assert all(f"#   {line}" in done.spec_path.read_text() for line in done.lines)


def test_mimic_needs_a_movable_leader(tmp_path):
    done = import_robot(ARM, tmp_path)
    text = done.spec_path.read_text().replace("joint: spin,", "joint: base_joint,")
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    with pytest.raises(SpecError, match="mimic needs another movable joint, not 'base_joint'"):
        load_spec(bad)


def test_strict_refuses_gaps(tmp_path):
    with pytest.raises(SpecError) as err:
        import_robot(ARM, tmp_path / "out", strict=True)
    assert "arm.urdf:58: inertia: " in str(err.value) and "(and 2 more errors)" in str(err.value)
    assert not (tmp_path / "out" / "arm.yaml").exists()


def test_import_is_deterministic(tmp_path):
    a, b = import_robot(ARM, tmp_path / "a"), import_robot(ARM, tmp_path / "b")
    assert a.spec_path.read_bytes() == b.spec_path.read_bytes()
    assert (tmp_path / "a/meshes/bracket.stl").read_bytes() == (
        tmp_path / "b/meshes/bracket.stl"
    ).read_bytes()


def test_package_dir_and_ros_package_path(tmp_path, monkeypatch):
    copy = tmp_path / "elsewhere" / "arm.urdf"
    copy.parent.mkdir()
    shutil.copy(ARM, copy)  # no package.xml above the copy: the walk-up finds nothing
    with pytest.raises(SpecError, match="unknown package 'pkg_demo'"):  # --strict: no drop
        import_robot(copy, tmp_path / "none", strict=True)
    import_robot(copy, tmp_path / "dir", package_dirs=(URDF,))
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(URDF))
    assert import_robot(copy, tmp_path / "env").meshes == 1


def test_xacro_is_expanded(tmp_path):
    done = import_robot(URDF / "arm.urdf.xacro", tmp_path, name="xacro_arm")
    spec, _doc = load_spec(done.spec_path)
    assert spec.root == "world" and [link.name for link in spec.links] == ["rod1", "rod2"]
    assert spec.joints[1].xyz == (0, 0, 0.3)
    assert spec.links[0].solid[0].size == (0.04, 0.04, 0.3)


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("malformed.urdf", "malformed.urdf:4: xml: malformed XML: Opening and ending tag mismatch"),
        ("cycle.urdf", "cycle.urdf:5: joint[ab]: the joints form a cycle"),
        ("missing_mesh.urdf", "missing_mesh.urdf:5: mesh: mesh file not found: meshes/nowhere"),
        ("unknown_package.urdf", "unknown_package.urdf:5: mesh: unknown package 'no_such_package'"),
    ],
)
def test_errors_are_one_line(tmp_path, name, message):
    args = ["import", str(URDF / name), "--out", str(tmp_path), "--strict"]  # no mesh drop
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2
    assert message in result.output and "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1
    assert not list(tmp_path.glob("*.yaml"))


def test_cli_writes_spec(tmp_path):
    result = CliRunner().invoke(
        main, ["import", str(ARM), "--name", "demo", "--out", str(tmp_path), "-q"]
    )
    assert result.exit_code == 0, result.output
    assert yaml.safe_load((tmp_path / "demo.yaml").read_text())["name"] == "demo"


def _legged(robot) -> bool:
    """package:// mesh URIs and eight or more movable joints, all revolute."""
    uris = corpus_pick.meshes(robot, "visual") + corpus_pick.meshes(robot, "collision")
    types = corpus_pick.movable(robot)
    packaged = bool(uris) and all(u.startswith("package://") for u in uris)
    return packaged and len(types) >= 8 and set(types) == {"revolute"}


def _drawn(link) -> bool:
    return link.find("visual") is not None or link.find("collision") is not None


def _collada_arm(robot) -> bool:
    """Movable joints, COLLADA visuals only, and a link with collision geometry but no visual."""
    uris = corpus_pick.meshes(robot, "visual")
    bare = [k for k in robot.iter("link") if _drawn(k) and k.find("visual") is None]
    dae = bool(uris) and all(u.lower().endswith(".dae") for u in uris)
    return dae and bool(bare) and bool(corpus_pick.movable(robot))


def test_corpus_floating_base_and_dae(tmp_path):
    """A corpus robot with package:// URIs imported on a floating base, and one with DAE
    visuals and a link without any (picked by those properties, corpus_pick.py)."""
    source = corpus_pick.pick(_legged)
    legged = import_robot(source, tmp_path / "legged", floating=True)
    spec, _doc = load_spec(legged.spec_path)
    assert spec.floating_base and spec.joints[0].type == "floating"
    urdf = ET.parse(source).getroot()
    assert sum(j.type == "revolute" for j in spec.joints) == len(corpus_pick.movable(urdf))
    source = corpus_pick.pick(_collada_arm)
    arm = import_robot(source, tmp_path / "arm")
    spec, _doc = load_spec(arm.spec_path)
    urdf = ET.parse(source).getroot()
    drawn = {k.get("name") for k in urdf.iter("link") if _drawn(k)}
    assert drawn <= {link.name for link in spec.links}  # the link without a visual too
    files = {p.file for link in spec.links for p in link.solid if p.shape == "mesh"}
    assert files and all(f.endswith(".stl") for f in files)
    for uri in corpus_pick.meshes(urdf, "visual"):
        assert (tmp_path / "arm" / "meshes" / f"{Path(uri).stem}.stl").is_file()


def test_gazebo_transmission_and_ros2_control_blocks_are_kept_verbatim(tmp_path):
    """Each block is the URDF's own text, in file order; one naming a missing link is left
    out with a report line (test_gaps_are_estimated_and_reported)."""
    done = import_robot(ARM, tmp_path)
    spec, _doc = load_spec(done.spec_path)
    source = ARM.read_text()
    assert [b.split(">", 1)[0].split()[0] for b in spec.urdf_blocks] == [
        "<transmission",
        "<gazebo",
        "<gazebo",
        "<ros2_control",
    ]
    for block in spec.urdf_blocks[:2]:
        assert block in source  # verbatim (no namespace declarations were in scope)
    assert '<ctrl:plugin name="arm_controller"' in spec.urdf_blocks[2]


def test_a_block_naming_a_missing_joint_is_a_one_line_spec_error(tmp_path):
    done = import_robot(ARM, tmp_path)
    text = done.spec_path.read_text().replace('<joint name="slide">', '<joint name="slid">')
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    with pytest.raises(SpecError, match="names joint 'slid', which the spec lacks") as info:
        load_spec(bad)
    assert "urdf_blocks[3]" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.slow
def test_imported_arm_builds(tmp_path, kit_factory):
    """The kit's URDF carries the blocks as the URDF had them, and the check sees a change."""
    from simkit.check.kit import Kit
    from simkit.check.urdf import check_urdf

    done = import_robot(ARM, tmp_path)
    result = kit_factory(str(done.spec_path))
    urdf = next(result.kit_dir.glob("urdf/*.urdf"))
    text = urdf.read_text()
    spec, _doc = load_spec(done.spec_path)
    assert all(block in text for block in spec.urdf_blocks)
    mjcf = next(result.kit_dir.glob("mjcf/*.xml")).read_text()  # the mimic's stiff equality
    assert 'joint1="spin_follow" joint2="spin"' in mjcf and 'solref="0.004 1"' in mjcf
    kit = tmp_path / "kit"
    shutil.copytree(result.kit_dir, kit)
    found = {f.check: f.ok for f in check_urdf(Kit.open(kit))}
    assert found["urdf.blocks"] and found["urdf.blocks.names"]
    tampered = kit / urdf.relative_to(result.kit_dir)
    tampered.write_text(text.replace("<mu1>0.9</mu1>", "<mu1>0.5</mu1>"))
    assert not {f.check: f.ok for f in check_urdf(Kit.open(kit))}["urdf.blocks"]


def test_large_cad_meshes_leave_the_step_out(tmp_path, monkeypatch):
    """Over the triangle budget the spec says `step: false`, with one report line."""
    from simkit.importer.fixups import step_budget

    small = import_robot(ARM, tmp_path / "a")
    assert load_spec(small.spec_path)[0].step is True
    data = yaml.safe_load(small.spec_path.read_text())
    count = step_budget.visual_triangles(data, small.spec_path.parent)
    assert count > 0
    monkeypatch.setattr(step_budget, "MAX_TRIANGLES", count - 1)
    big = import_robot(ARM, tmp_path / "b")
    assert load_spec(big.spec_path)[0].step is False
    assert [line for line in big.lines if f"{count:,} triangles" in line]


@pytest.mark.slow
def test_spec_step_false_builds_without_step(tmp_path):
    import json

    from simkit.pipeline import build

    spec = tmp_path / "planar_2r.yaml"
    text = (URDF.parent / "planar_2r.yaml").read_text()
    spec.write_text(text + "\nstep: false\n")
    result = build(str(spec), tmp_path / "out")
    assert not any(path.startswith("step/") for path in result.files)
    assert json.loads(result.files["robot.json"])["geometry"]["step"] is None


def test_a_second_visual_colour_is_reported_not_dropped_silently(tmp_path):
    """A kit link is one solid with one material: the first visual's colour wins, and each
    other colour gets a report line."""
    inertia = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
    urdf = tmp_path / "two_colours.urdf"
    urdf.write_text(
        '<robot name="two_colours"><link name="base"><inertial><mass value="1"/>'
        f"{inertia}</inertial>"
        '<visual><geometry><box size="0.1 0.1 0.1"/></geometry>'
        '<material name="red"><color rgba="1 0 0 1"/></material></visual>'
        '<visual><origin xyz="0 0 0.1"/><geometry><box size="0.1 0.1 0.1"/></geometry>'
        '<material name="blue"><color rgba="0 0 1 1"/></material></visual></link></robot>'
    )
    done = import_robot(urdf, tmp_path / "out")
    spec, _doc = load_spec(done.spec_path)
    assert {m.name: m.rgba for m in spec.materials}[spec.links[0].material] == (1, 0, 0, 1)
    line = next(line for line in done.lines if "colour 0 0 1 1" in line)
    assert line.startswith("two_colours.urdf:1: visual: changed:") and "1 0 0 1" in line


@pytest.mark.parametrize(
    ("block", "message"),
    [
        ("<gazebo><a></gazebo>", "not well-formed XML"),
        ("<link name='x'/>", "is not one of <gazebo>, <transmission>, <ros2_control>"),
        ('<?xml version="1.0"?><gazebo/>', "must start with <gazebo>"),
        ("<gazebo reference='nowhere'/>", "names link or joint 'nowhere'"),
    ],
)
def test_bad_urdf_blocks_are_refused_on_one_line(tmp_path, block, message):
    """A block goes verbatim inside the kit URDF's <robot>: it must be one element of the
    three tags, naming only what the spec has."""
    done = import_robot(ARM, tmp_path)
    spec = yaml.safe_load(done.spec_path.read_text())
    spec["urdf_blocks"] = [block]
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(spec, sort_keys=False))
    with pytest.raises(SpecError, match=message) as info:
        load_spec(bad)
    assert "urdf_blocks[0]" in str(info.value) and "\n" not in str(info.value)
