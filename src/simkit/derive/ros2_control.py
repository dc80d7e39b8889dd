"""Derive step for robots whose spec has a `ros2_control:` section (ECN report
002_e760a3794accbbd5.txt, section 4 steps 2-3, section 5 step 1): which joints get
controllers, the controller names per control mode, the extra ROS 2 packages the package
needs, and robot.json's `ros2_control` entry. `emit/ros2_control.py` formats the files."""

from __future__ import annotations

import re
from dataclasses import replace

from simkit.kitio import layout
from simkit.model.robot import Joint, Robot


def controller_base(joint: str) -> str:
    """Controller name stem of a joint: `joint_1` -> `joint1`, as the ECN 2R report names its
    controllers and topics (002_e760a3794accbbd5.txt section 5: joint1_position_controller,
    /joint1_position_controller/command); other names unchanged."""
    return re.sub(r"_(\d+)$", r"\1", joint)


def joints(robot: Robot) -> list[Joint]:
    """The joints ros2_control drives: every actuated movable joint, in tree order."""
    return [j for j in robot.movable_joints if j.actuated]


def controllers(robot: Robot) -> dict[str, list[str]]:
    """Controller names by control mode (what gazebo.launch.py spawns)."""
    rc = robot.ros2_control
    names = [j.name for j in joints(robot)]
    return {
        "position": [f"{controller_base(n)}_position_controller" for n in names]
        if rc.position_pid
        else [],
        "effort": [f"{controller_base(n)}_effort_controller" for n in names]
        if rc.effort_controllers
        else [],
    }


def exec_depends(robot: Robot) -> list[str]:
    """ROS 2 packages the URDF's plugin, controllers.yaml and gazebo.launch.py need."""
    rc = robot.ros2_control
    if rc is None:
        return []
    out = {
        "controller_manager",
        "gz_ros2_control",
        "joint_state_broadcaster",
        "ros_gz_bridge",
        "ros_gz_sim",
    }
    if rc.position_pid is not None:
        out.add("pid_controller")
    if rc.effort_controllers:
        out.add("effort_controllers")
    return sorted(out)


def derive_ros2_control(robot: Robot) -> Robot:
    """Derive step: the extra ROS 2 packages the package emitter (emit/ros2.py) must depend
    on, and robot.json's `ros2_control` entry (files, controllers, gains, estimates)."""
    rc = robot.ros2_control
    if rc is None:
        return robot
    merged = sorted(set(robot.products.ros2_exec_depends) | set(exec_depends(robot)))
    pid = rc.position_pid
    block = {
        "files": {
            "controllers": layout.CONTROLLERS_YAML,
            "gazebo_launch": layout.GAZEBO_LAUNCH,
        },
        "hardware_plugin": rc.hardware_plugin,
        "command_interfaces": list(rc.command_interfaces),
        "state_interfaces": list(rc.state_interfaces),
        "update_rate": rc.update_rate,
        "controllers": controllers(robot),
        "position_pid": None if pid is None else pid.model_dump(),
        "transmissions": {j.name: j.drive.gear_ratio if j.drive else 1.0 for j in joints(robot)},
        "gazebo_materials": dict(rc.gazebo_materials),
        "default_control": rc.default_control,
        "estimated": list(rc.estimated),
    }
    products = replace(robot.products, ros2_exec_depends=merged, ros2_control=block)
    return replace(robot, products=products)
