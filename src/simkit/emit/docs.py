"""Kit README.md and LICENSE.txt from Jinja templates; values arrive already formatted."""

from __future__ import annotations

import math
from functools import cache

import jinja2
import numpy as np

from simkit import layout
from simkit.emit import mjcf_world
from simkit.fmt import num
from simkit.kinematics import chain, quat_wxyz, rpy_matrix
from simkit.model import Robot
from simkit.resources import data_dir


@cache
def environment() -> jinja2.Environment:
    """The template environment shared by every text emitter."""
    from simkit.emit.escape import FILTERS

    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(data_dir("templates"))),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        autoescape=False,
    )
    env.filters.update(FILTERS)  # every value goes through its language's filter (escape.py)
    return env


def _deg(value: float | None) -> str:
    return "" if value is None else num(math.degrees(value), 4)


def context(robot: Robot) -> dict:
    """Formatted values for the README template."""
    axes = {(1.0, 0.0, 0.0): "x", (0.0, 1.0, 0.0): "y", (0.0, 0.0, 1.0): "z"}
    joints = [
        {
            "name": j.name,
            "parent": j.parent,
            "child": j.child,
            "axis": axes.get(tuple(j.axis), " ".join(num(a, 5) for a in j.axis)),
            "lower": _deg(j.lower),
            "upper": _deg(j.upper),
            "velocity": _deg(j.max_velocity),
            "effort_peak": num(j.effort_peak, 4) if j.effort_peak else "",
            "drive_peak": num(j.drive_peak_torque_at_joint, 4)
            if j.drive_peak_torque_at_joint
            else "",
            "armature": num(j.armature, 4),
        }
        for j in robot.movable_joints
    ]
    poses = {name: ", ".join(num(math.degrees(v), 4) for v in q) for name, q in robot.poses}
    demo_pose = "work" if "work" in dict(robot.poses) else "home"
    demo = [num(math.degrees(v), 6) for v in dict(robot.poses).get(demo_pose, ())]
    return {
        "robot": robot.name,
        "title": robot.title,
        "description": robot.description,
        "package": layout.kit_dir_name(robot.name),
        "urdf": layout.urdf(robot.name),
        "mjcf": layout.mjcf(robot.name),
        "joints": joints,
        "poses": poses,
        "mass": num(robot.total_mass, 4),
        "root": robot.root,
        "tool": robot.tool_frame or "",
        "n_movable": len(robot.movable_joints),
        "has_actuators": bool(robot.actuators) and mjcf_world.servos_in_main(robot),
        "demo_q": demo,
        "demo_pose": demo_pose,
        "sources": list(robot.sources),
        **_floating(robot),
        **_fk_snippet(robot),
    }


def _fk_snippet(robot: Robot) -> dict:
    """Which robot.json FK snippet the README can show. `fk` is "page" for the kit page's own
    snippet (pure-translation origins, tool frame = last link turned 180 deg about x),
    "general" when the movable joints form one chain to the tool frame, else ""."""
    tool = next((f for f in robot.frames if f.name == robot.tool_frame), None)
    movable = list(robot.movable_joints)
    if tool is None or not movable:
        return {"fk": "", "fk_pose": "", "fk_base": ""}
    try:
        path = [j for j in chain(robot, movable[0].parent, tool.parent) if j.movable]
    except ValueError:
        return {"fk": "", "fk_pose": "", "fk_base": ""}
    if path != movable:
        return {"fk": "", "fk_pose": "", "fk_base": ""}
    names = [name for name, _ in robot.poses]
    pose = "stretched" if "stretched" in names else next((n for n in names if n != "home"), "")
    page = (
        all(j.rpy == (0.0, 0.0, 0.0) for j in movable)
        and tool.xyz == (0.0, 0.0, 0.0)
        and np.allclose(rpy_matrix(tool.rpy), np.diag([1.0, -1.0, -1.0]))
    )
    return {
        "fk": "page" if page else "general",
        "fk_pose": pose or "home",
        "fk_base": movable[0].parent,
    }


def _floating(robot: Robot) -> dict:
    """Values for the floating-base quickstart (the loading snippets of the robot's MuJoCo
    reference): free-joint start, an example joint, sensor names, the file with the servos."""
    joint = robot.floating_joint
    scene = "" if mjcf_world.servos_in_main(robot) else layout.mjcf_scene(robot.name)
    movable = robot.movable_joints
    return {
        "floating": None
        if joint is None
        else {
            "joint": joint.name,
            "child": joint.child,
            "xyz": ", ".join(num(v) for v in joint.xyz),
            "quat": ", ".join(num(v) for v in quat_wxyz(rpy_matrix(joint.rpy))),
        },
        "fixed_base": "False" if joint is not None else "True",
        "scene": scene,
        "control_mjcf": scene or layout.mjcf(robot.name),
        "home_key": bool(scene) and "home" in dict(robot.poses),
        "example_joint": movable[0].name if movable else "",
        "sensors": [f'"{s.name}"' for s in (robot.mjcf.sensors if robot.mjcf else ())],
    }


def emit(robot: Robot) -> dict[str, bytes]:
    """`README.md` and `LICENSE.txt`."""
    env, ctx = environment(), context(robot)
    return {
        layout.README: env.get_template("kit_README.md.j2").render(ctx).encode("utf-8"),
        layout.LICENSE: env.get_template("LICENSE.txt.j2").render(ctx).encode("utf-8"),
    }
