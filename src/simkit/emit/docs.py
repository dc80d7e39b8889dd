"""Kit README.md and LICENSE.txt from Jinja templates; values arrive already formatted."""

from __future__ import annotations

import math

import numpy as np

from simkit.derive.ros2_control import controllers
from simkit.derive.solids import CIRCULAR_SEGMENTS
from simkit.emit import mjcf_world, robot_json, training
from simkit.emit.step import step_origin
from simkit.emit.templating import environment
from simkit.kitio import layout
from simkit.kitio.fmt import num
from simkit.model.kinematics import chain, quat_wxyz, rpy_matrix
from simkit.model.robot import Robot


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
        "step": layout.step(robot.name),
        "step_origin": step_origin(robot),
        "step_left_out": list(robot.products.step_left_out),
        "segments": CIRCULAR_SEGMENTS,
        "loops": [f"`{lp.link1}` and `{lp.link2}` ({lp.name})" for lp in robot.loops],
        **_floating(robot),
        **_gpu(robot),
        **training.readme(robot),
        **_fk_snippet(robot),
        **_page_extras(robot),
    }


def _gpu(robot: Robot) -> dict:
    """Values for the README's GPU section (robot.json `gpu_scene`)."""
    block = robot_json.gpu_scene(robot)
    if block is None:
        return {"gpu": None, "gpu_none": None}
    if block["file"] is None:  # no GPU scene: the one line saying why
        return {"gpu": None, "gpu_none": block["note"]}
    return {
        "gpu": {
            **block,
            "floor_pairs": len(block["floor_pairs"]),
            "self_pairs": block["pairs"] - len(block["floor_pairs"]),
        },
        "gpu_none": None,
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


#: The Rosie kit page's quickstart target, J1..J6 in deg (000_5f76ade803e16979.txt, Quickstart).
PAGE_TARGET_DEG = ("30", "45", "-10", "0", "-35", "0")


def _page_extras(robot: Robot) -> dict:
    """The kit page's own snippets for an arm with its conventions (`fk` "page"): its target,
    the IK-cases check, and the paths of the benchmark files."""
    page = _fk_snippet(robot)["fk"] == "page" and len(robot.movable_joints) == 6
    movable = robot.movable_joints
    return {
        "page_target": list(PAGE_TARGET_DEG) if page else [],
        "joint_span": f"{movable[0].name}..{movable[-1].name}" if movable else "",
        "last_link": movable[-1].child if movable else "",
        "ik_cases": layout.IK_CASES if page else "",
        "benchmark": "benchmark/" if page else "",
        "self_collision": True,
        "mujoco_page": _mujoco_page(robot),
        "gazebo": _gazebo(robot),
    }


def _gazebo(robot: Robot) -> dict | None:
    """Controllers of launch/gazebo.launch.py per `control:=` mode, when the kit has it."""
    if robot.ros2_control is None:
        return None

    names = controllers(robot)
    return {
        "default": robot.ros2_control.default_control,
        "position": [f"`{n}`" for n in names["position"]],
        "effort": [f"`{n}`" for n in names["effort"]],
    }


#: The names the Asimov MuJoCo reference's snippets use (001_71a395c46b8a5939.txt, "Loading
#: and Using the Model"): a robot that has them all gets those snippets in its README.
MUJOCO_PAGE_NAMES = {
    "joint": "left_knee_joint",
    "sensors": ("imu_ang_vel", "imu_lin_vel", "imu_quat"),
}
MUJOCO_PAGE = {
    # the document's title, as the spec's `sources` names it (the kit ships no copy of it)
    "source": "the Asimov MuJoCo model (asimov.xml) reference",
    "page_path": "sim-model/xmls/asimov.xml",
    "knee_geom": "left_knee_link_collision",
}


def _mujoco_page(robot: Robot) -> dict | None:
    """The Asimov reference's snippets apply when the robot has every name they use."""
    joints = {j.name for j in robot.joints}
    sensors = {s.name for s in (robot.mjcf.sensors if robot.mjcf else ())}
    if MUJOCO_PAGE_NAMES["joint"] in joints and set(MUJOCO_PAGE_NAMES["sensors"]) <= sensors:
        return MUJOCO_PAGE
    return None


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
            "balance": robot.needs_active_balance or "",
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
