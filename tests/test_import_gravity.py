"""The importer's home for fixed bases (issue 15): a pose the kit's servos can hold against
gravity (gravity.py: some arms' shoulders cannot hold them out level), and
free of contact between the visual pieces the kit's collision pieces are grown to cover
(home.py's second search: a humanoid hand's fingers)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simkit.importer import import_robot
from simkit.importer.fixups import gravity
from simkit.model.dynamics import gravity_torques
from simkit.model.resolve import resolve
from simkit.spec.validate import load_spec


def _link(name: str, size: str, xyz: str = "0 0 0", visual: tuple = ()) -> str:
    """A box link of 2 kg; `visual` = (size, xyz) gives it a different visual box."""
    shape = f'<origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry>'
    seen = (
        shape
        if not visual
        else f'<origin xyz="{visual[1]}"/><geometry><box size="{visual[0]}"/></geometry>'
    )
    return (
        f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value="2"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<visual>{seen}</visual><collision>{shape}</collision></link>"
    )


def _joint(name, kind, child, xyz, axis="0 0 1", effort=50.0) -> str:
    limit = f'<limit lower="-1.5" upper="1.5" effort="{effort}" velocity="2"/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="base"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>{limit if kind != "fixed" else ""}</joint>'
    )


def _import(tmp_path: Path, body: str):
    urdf = tmp_path / "r.urdf"
    urdf.write_text(f'<?xml version="1.0"?>\n<robot name="r">\n{body}\n</robot>\n')
    done = import_robot(urdf, tmp_path / "out")
    spec, _doc = load_spec(done.spec_path)
    robot = resolve(spec, done.spec_path.read_text().encode(), done.spec_path.name)
    return robot, dict(robot.poses)["home"], done.lines


def _arm(effort: float) -> str:
    """A 2 kg arm 0.5 m long on a pitch joint 0.7 m up, level at 0: 4.9 N m to hold there."""
    return "\n".join(
        [
            _link("base", "0.4 0.4 0.05", "0 0 -0.025"),
            _link("arm", "0.5 0.04 0.04", "0.25 0 0"),
            _joint("pitch", "revolute", "arm", "0 0 0.7", "0 1 0", effort),
        ]
    )


def test_home_moves_where_a_weak_joint_holds_its_arm(tmp_path):
    robot, home, lines = _import(tmp_path, _arm(5.0))  # level: 98 % of the effort
    joint = robot.joint("pitch")
    assert joint.effort_peak == 5.0  # the URDF's effort is kept
    load = abs(gravity_torques(robot, home)["pitch"]) / joint.effort_peak
    assert load <= gravity.LIMIT
    assert abs(home[0]) > 1.0  # the arm hangs (or stands) rather than staying level
    assert any("against gravity" in line and "pitch: 0 ->" in line for line in lines)


def test_home_stays_where_the_joint_holds_its_arm(tmp_path):
    _robot, home, lines = _import(tmp_path, _arm(50.0))  # level: 10 % of the effort
    assert np.allclose(home, 0.0)
    assert not any("home:" in line for line in lines)


def test_home_clears_visual_pieces_the_collision_leaves_apart(tmp_path):
    # an arm turning about z whose collision box stops at 0.1 m but whose visual box reaches
    # into a post fixed at 0.3 m (a humanoid hand's fingers: collision meshes placed apart from
    # their visual ones); the kit grows its pieces to cover the visual, so they would touch
    body = "\n".join(
        [
            _link("base", "0.4 0.4 0.05", "0 0 -0.025"),
            _link("post", "0.05 0.05 0.1"),
            _joint("post_fix", "fixed", "post", "0.3 0 0.1"),
            _link("arm", "0.1 0.04 0.04", "0.05 0 0", visual=("0.3 0.04 0.04", "0.15 0 0")),
            _joint("yaw", "revolute", "arm", "0 0 0.1"),
        ]
    )
    _robot, home, lines = _import(tmp_path, body)
    # clear of the post: the visual's far corners (0.3 m out, 0.02 m wide) miss its 0.025 m
    assert abs(home[0]) > np.arctan2(0.045, 0.275)
    assert any("home:" in line and "yaw: 0 ->" in line for line in lines)


def test_search_lets_a_pair_overlapping_at_the_start_go_a_little_deeper():
    # an arm's elbow: the hulls of two visual pieces overlap by 48 mm at the start and by
    # 0.1 mm more as the elbow folds; the kit's pieces, which follow the mesh, stay apart
    search = object.__new__(gravity.Search)
    search.near = {(0, 1): -0.048, (2, 3): 0.01}
    assert search.allowed((0, 1), -0.048 - 0.0001)
    assert not search.allowed((0, 1), -0.048 - 2 * gravity.SLACK)
    assert search.allowed((2, 3), 0.003)  # apart at the start: the clearance, no slack
    assert not search.allowed((2, 3), 0.003 - gravity.SLACK / 2)
    assert not search.allowed((4, 5), 0.0)  # a new pair inside the clearance


def _gripper(multiplier: float, lower: float, upper: float) -> str:
    """A finger on a 0..0.5 rad leader and a follower mimicking it with `multiplier` whose
    URDF limits are `lower`..`upper`."""
    follower = (
        '<joint name="follow" type="revolute"><parent link="base"/><child link="f2"/>'
        '<origin xyz="-0.1 0 0.1"/><axis xyz="0 1 0"/>'
        f'<limit lower="{lower}" upper="{upper}" effort="5" velocity="2"/>'
        f'<mimic joint="lead" multiplier="{multiplier}" offset="0"/></joint>'
    )
    leader = (
        '<joint name="lead" type="revolute"><parent link="base"/><child link="f1"/>'
        '<origin xyz="0.1 0 0.1"/><axis xyz="0 1 0"/>'
        '<limit lower="0" upper="0.5" effort="5" velocity="2"/></joint>'
    )
    return "\n".join(
        [
            _link("base", "0.4 0.4 0.05", "0 0 -0.025"),
            _link("f1", "0.02 0.02 0.1", "0 0 0.05"),
            _link("f2", "0.02 0.02 0.1", "0 0 0.05"),
            leader,
            follower,
        ]
    )


def test_mimic_follower_gets_the_range_its_mimic_maps_the_leader_to(tmp_path):
    # a parallel gripper's finger follower: multiplier -1 on a 0..0.548 leader, limits
    # 0..0.548, so any opening puts it out of its range
    robot, _home, lines = _import(tmp_path, _gripper(-1.0, 0.0, 0.5))
    joint = robot.joint("follow")
    assert (joint.lower, joint.upper) == (-0.5, 0.0)
    assert {"lower", "upper"} <= set(joint.estimated)
    found = [line for line in lines if "do not hold the range of its mimic" in line]
    assert len(found) == 1 and "-0.5..0" in found[0]


def test_mimic_follower_whose_limits_hold_the_mapped_range_is_kept(tmp_path):
    robot, _home, lines = _import(tmp_path, _gripper(1.0, 0.0, 0.6))
    joint = robot.joint("follow")
    assert (joint.lower, joint.upper) == (0.0, 0.6)
    assert "lower" not in joint.estimated
    assert not any("range of its mimic" in line for line in lines)
