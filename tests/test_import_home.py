"""Fixed-base corpus repairs (issue 15): the "always in contact" rule the derive stage, the
check and the importer's home search share (MoveIt's min_collision_fraction and a 1 um touch),
and one USD articulation for a massless root frame holding several links (a mobile manipulator)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from simkit.importer import import_robot
from simkit.model.resolve import resolve
from simkit.spec.validate import load_spec


def _box(name: str, size: str, xyz: str = "0 0 0", mass: float | None = 1.0) -> str:
    geometry = f'<origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry>'
    inertial = (
        f'<inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
    )
    return (
        f'<link name="{name}">{inertial}<visual>{geometry}</visual>'
        f"<collision>{geometry}</collision></link>"
    )


def _joint(name, kind, parent, child, xyz, axis="0 0 1", lower=-1.0, upper=1.0) -> str:
    limit = f'<limit lower="{lower}" upper="{upper}" effort="50" velocity="2"/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>{limit if kind != "fixed" else ""}</joint>'
    )


def _robot(tmp_path: Path, body: str):
    urdf = tmp_path / "r.urdf"
    urdf.write_text(f'<?xml version="1.0"?>\n<robot name="r">\n{body}\n</robot>\n')
    done = import_robot(urdf, tmp_path / "out")
    spec, _doc = load_spec(done.spec_path)
    text = done.spec_path.read_text()
    return resolve(spec, text.encode(), done.spec_path.name), done


# A base with a wall fixed to it; a block sliding along the wall face on face (a gripper's finger
# blocks); an arm turning about z into a wide post fixed to the base, out of it only over the
# last 2 % of its range (a fingertip in its hand's safety box: 1.419 rad and up); a
# small link that never touches anything.
ALWAYS = "\n".join(
    [
        _box("base", "0.4 0.4 0.05", "0 0 -0.025"),
        _box("wall", "0.02 0.2 0.1", "-0.01 0 0.05"),
        _joint("wall_fix", "fixed", "base", "wall", "-0.1 0 0"),
        _box("block", "0.02 0.05 0.05", "0.01 0 0.05"),
        _joint("slide", "prismatic", "base", "block", "-0.1 0 0.01", "0 1 0", -0.05, 0.05),
        _box("post", "0.25 0.6 0.1", "0.175 0 0"),
        _joint("post_fix", "fixed", "base", "post", "0.1 0.1 0.1"),
        _box("arm", "0.2 0.04 0.04", "0.1 0 0"),
        _joint("hinge", "revolute", "base", "arm", "0.1 0.1 0.1", "0 0 1", -1.0, 1.47),
        _box("free", "0.02 0.02 0.05", "0 0 0.025"),
        _joint("far", "revolute", "base", "free", "-0.15 -0.15 0.05", "0 0 1"),
    ]
)


def test_always_rule_counts_touching_faces_and_almost_always(tmp_path):
    from simkit.derive.collision_pairs import (
        ALWAYS_FRACTION,
        TOUCH,
        always_pairs,
        configurations,
    )
    from simkit.importer.fixups import collide

    robot, _done = _robot(tmp_path, ALWAYS)
    q = configurations(robot, robot.seed, 1000)
    always = always_pairs(robot, q)
    assert ("block", "wall") in always  # face on face at every q: touching within TOUCH
    assert ("arm", "post") in always  # apart in a few per cent of q only
    assert not any("free" in p for p in always)
    # the importer's home search and the derive stage share the rule
    assert (collide.ALWAYS_FRACTION, collide.TOUCH) == (ALWAYS_FRACTION, TOUCH)
    start = np.zeros(len(robot.movable_joints))
    found = collide.always_touching(robot, tmp_path / "out", start, lambda v: v)
    assert {("block", "wall"), ("arm", "post")} <= set(found)


def test_always_rule_keeps_a_pair_that_separates_often(tmp_path):
    """The same arm over a range where it leaves the post a third of the time is no always
    pair: the kit keeps its contacts, and the home search must move it out."""
    from simkit.derive.collision_pairs import always_pairs, configurations

    body = ALWAYS.replace('lower="-1.0" upper="1.47"', 'lower="-1.0" upper="2.5"')
    assert body != ALWAYS
    robot, done = _robot(tmp_path, body)
    always = always_pairs(robot, configurations(robot, robot.seed, 1000))
    assert ("arm", "post") not in always and ("block", "wall") in always
    spec = yaml.safe_load(done.spec_path.read_text())
    names = [j["name"] for j in spec["joints"] if j["type"] != "fixed"]
    home = dict(zip(names, spec["poses"]["home"], strict=True))
    assert home["hinge"] > 1.42  # turned out of the post
    assert home["slide"] == 0.0  # the always pair is left alone


def test_massless_root_frame_with_several_fixed_links_is_one_usd_articulation(tmp_path):
    from pxr import Sdf, Usd, UsdPhysics

    from simkit.check.usd import parse_physics
    from simkit.emit.usd import stage_text

    body = "\n".join(
        [
            '<link name="footprint"/>',
            _box("base", "0.4 0.4 0.1"),
            _joint("base_fix", "fixed", "footprint", "base", "0 0 0.1"),
            _box("cover", "0.1 0.1 0.02"),
            _joint("cover_fix", "fixed", "footprint", "cover", "0.1 0 0.2"),
            _box("arm", "0.05 0.05 0.3", "0 0 0.15"),
            _joint("shoulder", "revolute", "base", "arm", "0 0 0.1"),
        ]
    )
    robot, _done = _robot(tmp_path, body)
    assert robot.root == "footprint"
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.ImportFromString(stage_text(robot))
    stage = Usd.Stage.Open(layer)
    cover = UsdPhysics.FixedJoint(stage.GetPrimAtPath("/r/joints/cover_fix"))
    assert [str(t) for t in cover.GetBody0Rel().GetTargets()] == ["/r/base"]
    # 0.1 0 0.2 less base_fix 0 0 0.1 (float32)
    assert np.allclose(cover.GetLocalPos0Attr().Get(), (0.1, 0.0, 0.1), atol=1e-7)
    arts = parse_physics(stage).get(UsdPhysics.ObjectType.Articulation, ([], []))[1]
    assert len(arts) == 1
    assert {str(b) for b in arts[0].articulatedBodies} >= {"/r/base", "/r/cover", "/r/arm"}
