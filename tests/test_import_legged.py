"""`simkit import --floating-base` (issue 15): the kit must stand. Small handwritten URDFs:
links that always touch are excluded, home leaves self-contact with the feet kept, a URDF
without collision gets its visual hulls, rotor placeholders become continuous joints, and a
jointless robot gets no tool frame."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from simkit.importer import import_robot
from simkit.spec.validate import load_spec

REPO = Path(__file__).resolve().parents[1]


def _box(name: str, size: str, xyz: str = "0 0 0", mass: float = 1.0, collision=True) -> str:
    geometry = f'<origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry>'
    return (
        f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<visual>{geometry}</visual>"
        + (f"<collision>{geometry}</collision>" if collision else "")
        + "</link>"
    )


def _joint(name: str, parent: str, child: str, xyz: str, axis: str, limit: str = "1") -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/>'
        f'<child link="{child}"/><origin xyz="{xyz}"/><axis xyz="{axis}"/>'
        f'<limit lower="-{limit}" upper="{limit}" effort="50" velocity="2"/></joint>'
    )


def _biped(collision: bool = True) -> str:
    """A box body on two box legs, and an arm whose box hangs through the left leg at 0."""
    return (
        '<robot name="biped">'
        + _box("body", "0.3 0.3 0.1", collision=collision)
        + _box("left_leg", "0.05 0.05 0.5", "0 0 -0.25", collision=collision)
        + _box("right_leg", "0.05 0.05 0.5", "0 0 -0.25", collision=collision)
        + _box("arm", "0.05 0.05 0.4", "0 0 -0.2", 0.5, collision=collision)
        + _joint("left_hip", "body", "left_leg", "0 0.1 -0.05", "0 1 0")
        + _joint("right_hip", "body", "right_leg", "0 -0.1 -0.05", "0 1 0")
        + _joint("shoulder", "body", "arm", "0 0.13 0", "1 0 0", "1.5")
        + "</robot>"
    )


def _write(tmp_path: Path, text: str, name: str = "robot.urdf") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_floating_home_leaves_self_contact_feet_kept(tmp_path):
    done = import_robot(_write(tmp_path, _biped()), tmp_path / "out", floating=True)
    spec, _doc = load_spec(done.spec_path)
    names = [j.name for j in spec.joints if j.type == "revolute"]
    home = dict(zip(names, spec.poses["home"], strict=True))
    assert home["left_hip"] == 0.0 and home["right_hip"] == 0.0  # the feet stay put
    assert abs(home["shoulder"]) > 0.05  # the arm swings out of the leg
    assert any("home: at the first guess" in line for line in done.lines)
    base = spec.joints[0]
    assert base.type == "floating" and base.xyz[2] == 0.55  # feet on the floor


def test_always_touching_pairs_are_found(tmp_path):
    """Two links whose boxes overlap at every configuration (a thigh inside its hip yaw's
    box, as a humanoid's collision hulls do), and a pair that separates."""
    from simkit.derive.collision_pairs import always_pairs, configurations, welded_pairs
    from simkit.model.resolve import resolve

    urdf = (
        '<robot name="hip">'
        + _box("body", "0.3 0.3 0.1")
        + _box("hip", "0.2 0.2 0.2", "0 0 -0.1")
        + _box("thigh", "0.05 0.05 0.4", "0 0 -0.1")  # its top inside the body
        + _box("arm", "0.05 0.05 0.2", "0 0 -0.1")
        + _joint("yaw", "body", "hip", "0 0 -0.05", "0 0 1")
        + _joint("pitch", "hip", "thigh", "0 0 -0.05", "0 1 0", "0.3")
        + _joint("shoulder", "body", "arm", "0 0.2 0", "1 0 0", "3")
        + "</robot>"
    )
    done = import_robot(_write(tmp_path, urdf), tmp_path / "out", floating=False)  # bolted
    text = done.spec_path.read_text()
    spec, _doc = load_spec(done.spec_path)
    robot = resolve(spec, text.encode(), done.spec_path.name)
    q = configurations(robot, 0, 200)
    assert always_pairs(robot, q) == [("body", "thigh")]
    # body is welded to the world: MuJoCo's parent filter skips the world, so body and hip
    # do collide unless excluded (the kit excludes them as a jointed pair)
    assert ("body", "hip") not in welded_pairs(robot)


def test_floating_urdf_without_collision_collides_with_its_visuals(tmp_path):
    path = _write(tmp_path, _biped(collision=False))
    done = import_robot(path, tmp_path / "floating", floating=True)
    links = yaml.safe_load(done.spec_path.read_text())["links"]
    assert all(link["collision"] == "mesh" and "collision" in link["estimated"] for link in links)
    assert any("no <collision> in the URDF" in line for line in done.lines)
    fixed = import_robot(path, tmp_path / "fixed", floating=False)
    links = yaml.safe_load(fixed.spec_path.read_text())["links"]
    assert all(link["collision"] == "primitives" for link in links)  # as the URDF says


def test_revolute_limits_beyond_two_turns_import_as_continuous(tmp_path):
    urdf = (
        '<robot name="rotor">'
        + _box("frame", "0.3 0.3 0.05")
        + _box("prop", "0.25 0.02 0.005", mass=0.01)
        + _joint("spin", "frame", "prop", "0 0 0.05", "0 0 1", "1e16")
        + "</robot>"
    )
    done = import_robot(_write(tmp_path, urdf), tmp_path / "out", floating=True)
    spec, _doc = load_spec(done.spec_path)
    spin = next(j for j in spec.joints if j.name == "spin")
    assert spin.type == "continuous" and spin.lower is None
    assert any("imported as continuous" in line for line in done.lines)


def test_jointless_floating_robot_has_no_tool_frame(tmp_path):
    urdf = '<robot name="quad">' + _box("frame", "0.4 0.4 0.1") + "</robot>"
    done = import_robot(_write(tmp_path, urdf), tmp_path / "out", floating=True)
    spec = yaml.safe_load(done.spec_path.read_text())
    assert "tool_frame" not in spec and spec["floating_base"] is True


def test_open_mesh_hull_is_a_solid_at_stl_precision():
    """A thin open part (a propeller blade): its hull, written as float32 STL, is closed."""
    import trimesh

    from simkit.importer.translate.meshes import _is_solid, closed_solid

    rng = np.random.default_rng(3)
    points = rng.random((400, 3)) * (0.25, 0.03, 0.01)
    blade = trimesh.Trimesh(points, rng.integers(0, 400, (300, 3)), process=False)
    vertices, faces, repair = closed_solid(blade)
    assert repair == "hull"
    back = trimesh.load(
        trimesh.util.wrap_as_stream(trimesh.Trimesh(vertices, faces).export(file_type="stl")),
        file_type="stl",
    )
    assert _is_solid(back.vertices, back.faces)


def test_corpus_script_takes_any_folder_with_default_flags(tmp_path):
    """scripts/import_corpus.py: any folder, --exclude globs, --movable-only; no robot
    lists; a refusal keeps the invariant only as one line naming the URDF."""
    spec = importlib.util.spec_from_file_location("corpus", REPO / "scripts" / "import_corpus.py")
    corpus = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(corpus)
    moving = '<robot name="a"><link name="a"/><link name="b"/><joint name="j" type="revolute">'
    moving += '<parent link="a"/><child link="b"/></joint></robot>'
    (tmp_path / "arm").mkdir()
    (tmp_path / "arm" / "arm.urdf").write_text(moving)
    (tmp_path / "generated_urdfs").mkdir()
    (tmp_path / "generated_urdfs" / "x.urdf").write_text(moving)
    (tmp_path / "block.urdf").write_text('<robot name="b"><link name="b"/></robot>')
    found = corpus.urdfs(tmp_path, ["generated_urdfs/*"], movable_only=True)
    assert [p.relative_to(tmp_path).as_posix() for p in found] == ["arm/arm.urdf"]
    assert len(corpus.urdfs(tmp_path, [], movable_only=False)) == 3
    assert corpus._name(Path("humanoid_data/robots/humanoid-full.v2.urdf")) == (
        "humanoid_data_robots_humanoid_full"
    )
    long = corpus._name(Path("a_very_long_folder_name/another_long_folder/robot_name.urdf"))
    assert len(long) <= 48 and long != corpus._name(Path("a_very_long_folder_name/x.urdf"))
    urdf = tmp_path / "arm" / "arm.urdf"
    assert corpus._refusal(urdf, "simkit: error: arm.urdf:3: joint[j]: bad\n") == ""
    assert corpus._refusal(urdf, "Traceback (most recent call last):\n  x\n") == "traceback"
    assert corpus._refusal(urdf, "simkit: error: /tmp/x.yaml: bad\n") != ""
    assert not hasattr(corpus, "FLOATING")


def _walker() -> str:
    """Two legs whose thighs reach up into the body past a hip-yaw link: body and thigh
    touch in every configuration (as a humanoid's hip hulls do), and the arm starts in a leg."""
    legs = ""
    for side, y in (("left", 0.1), ("right", -0.1)):
        legs += (
            _box(f"{side}_yaw", "0.06 0.06 0.04", "0 0 -0.02", 0.3)
            + _box(f"{side}_thigh", "0.05 0.05 0.5", "0 0 -0.2", 2.0)
            + _joint(f"{side}_hip_yaw", "body", f"{side}_yaw", f"0 {y} -0.05", "0 0 1", "0.3")
            + _joint(f"{side}_hip", f"{side}_yaw", f"{side}_thigh", "0 0 -0.04", "0 1 0", "0.3")
        )
    return (
        '<robot name="walker">'
        + _box("body", "0.3 0.3 0.1", mass=5.0)
        + legs
        + _box("arm", "0.05 0.05 0.3", "0 0 -0.15", 0.5)
        + _joint("shoulder", "body", "arm", "0 0.13 0", "1 0 0", "1.5")
        + "</robot>"
    )


@pytest.mark.slow
def test_imported_walker_stands(tmp_path, kit_factory):
    """The kit of a floating import passes every check, legged.stand included, with the
    always-touching body-thigh pairs excluded (and mjcf.excludes verifying they touch)."""
    done = import_robot(_write(tmp_path, _walker()), tmp_path / "out", floating=True)
    result = kit_factory(str(done.spec_path))
    doc = json.loads((result.kit_dir / "robot.json").read_text())
    assert doc["collision_pairs"]["always"] == [["body", "left_thigh"], ["body", "right_thigh"]]
    assert {f.check for f in result.findings if f.check.startswith("legged.")} >= {
        "legged.stand.height",
        "legged.drop.floor",
    }


@pytest.mark.slow
def test_imported_rigid_quadrotor_rests(tmp_path, kit_factory):
    """No joints at all: every check runs (legged.stand without servos: it must rest)."""
    urdf = '<robot name="quad">' + _box("frame", "0.4 0.4 0.1", mass=1.5) + "</robot>"
    done = import_robot(_write(tmp_path, urdf), tmp_path / "out", floating=True)
    result = kit_factory(str(done.spec_path))
    assert "legged.stand.height" in {f.check for f in result.findings}


def test_flying_arm_rests_on_its_frame(tmp_path):
    """A frame with a thin two-link arm hanging below: balanced on the arm's tip it cannot
    rest, so home folds the arm up and the frame carries the weight (the arm's servos do not)."""
    from simkit.importer.fixups.stance import MARGIN, Support
    from simkit.model.resolve import resolve

    urdf = (
        '<robot name="drone">'
        + _box("frame", "0.4 0.4 0.05", mass=1.5)
        + _box("upper", "0.01 0.01 0.2", "0 0 -0.1", 0.05)
        + _box("lower", "0.01 0.01 0.2", "0 0 -0.1", 0.05)
        + _joint("j1", "frame", "upper", "0 0 0.02", "0 1 0", "2.5")  # through the frame
        + _joint("j2", "upper", "lower", "0 0 -0.2", "0 1 0", "2.5")
        + "</robot>"
    )
    done = import_robot(_write(tmp_path, urdf), tmp_path / "out", floating=True)
    spec, doc = load_spec(done.spec_path)
    robot = resolve(spec, doc.text.encode(), done.spec_path.name)
    support = Support(robot, done.spec_path.parent)
    assert support.margin([0.0, 0.0]) < MARGIN  # the first guess stands on the arm's tip
    home = spec.poses["home"]
    assert home != (0.0, 0.0) and support.margin(home, frame_only=True) >= MARGIN


def test_mujoco_parent_filter_skips_a_world_welded_parent():
    """The fact welded_pairs relies on: a jointed child touches its world-welded parent, but
    not its parent on a free joint."""
    import mujoco

    xml = """<mujoco><worldbody>
    <body name="fixed"><geom type="box" size=".2 .2 .2"/>
      <body name="a"><joint type="hinge"/><geom type="box" size=".1 .1 .1" pos="0 0 .1"/></body>
    </body>
    <body name="free" pos="2 0 0"><freejoint/><geom type="box" size=".2 .2 .2"/>
      <body name="b"><joint type="hinge"/><geom type="box" size=".1 .1 .1" pos="0 0 .1"/></body>
    </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    pairs = {
        (model.body(model.geom_bodyid[g1]).name, model.body(model.geom_bodyid[g2]).name)
        for g1, g2 in data.contact.geom[: data.ncon]
    }
    assert pairs == {("fixed", "a")}
