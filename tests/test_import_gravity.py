"""The importer's home for fixed bases (issue 15): a pose the kit's servos can hold against
gravity (gravity.py: Baxter's and PR2's shoulders cannot hold their arms out level), and
free of contact between the visual pieces the kit's collision pieces are grown to cover
(home.py's second search: Alex's Sake fingers)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simkit.importer import gravity, import_robot
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
    # into a post fixed at 0.3 m (Alex's Sake fingers: collision meshes placed apart from
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
