"""Rigid-body quantities the emitters need but must not compute: reflected inertia about each
joint axis, gravity torques, and the position-servo gains derived from them."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from simkit.model.kinematics import forward
from simkit.model.robot import Actuator, Robot

GRAVITY = np.array([0.0, 0.0, -9.81])
#: Servo stiffness: the joint's peak output torque per this many radians of error (kit page,
#: "Simulation parameters": gains are effort_peak per 0.01 rad, critically damped).
SERVO_ERROR_RAD = 0.01


def subtree_links(robot: Robot, joint_name: str) -> list[str]:
    """Names of every link moved by a joint (its child and all descendants)."""
    start = robot.joint(joint_name).child
    children: dict[str, list[str]] = {}
    for j in robot.joints:
        children.setdefault(j.parent, []).append(j.child)
    out, stack = [], [start]
    while stack:
        node = stack.pop()
        out.append(node)
        stack.extend(children.get(node, ()))
    order = {name: i for i, name in reversed(list(enumerate(lnk.name for lnk in robot.links)))}
    return sorted(out, key=order.__getitem__)


def axis_inertia(robot: Robot, joint_name: str, q=None, extra=()) -> float:
    """Inertia (kg m^2) about a revolute joint's axis of everything it moves, at pose q,
    excluding armature. `extra` adds point-mass-with-inertia bodies: (link, mass, com, tensor)."""
    poses = forward(robot, q)
    joint = robot.joint(joint_name)
    frame = poses[joint.child]
    axis = frame[:3, :3] @ np.asarray(joint.axis)
    origin = frame[:3, 3]
    total = 0.0
    bodies = [
        (link.name, link.inertial.mass, np.asarray(link.inertial.com), link.inertial.tensor())
        for link in robot.links
        if link.inertial is not None
    ] + [(name, m, np.asarray(c), np.asarray(t)) for name, m, c, t in extra]
    moved = set(subtree_links(robot, joint_name))
    for name, mass, com, tensor in bodies:
        if name not in moved:
            continue
        rot = poses[name][:3, :3]
        r = poses[name][:3, :3] @ com + poses[name][:3, 3] - origin
        inertia_world = rot @ tensor @ rot.T
        r_perp = r - axis * (axis @ r)
        total += float(axis @ inertia_world @ axis + mass * (r_perp @ r_perp))
    return total


def gravity_torques(robot: Robot, q=None, extra=()) -> dict[str, float]:
    """Torque (N m) each movable joint must apply to hold pose q against gravity."""
    poses = forward(robot, q)
    bodies = [
        (link.name, link.inertial.mass, np.asarray(link.inertial.com))
        for link in robot.links
        if link.inertial is not None
    ] + [(name, m, np.asarray(c)) for name, m, c, _ in extra]
    out: dict[str, float] = {}
    for joint in robot.movable_joints:
        frame = poses[joint.child]
        axis = frame[:3, :3] @ np.asarray(joint.axis)
        origin = frame[:3, 3]
        moved = set(subtree_links(robot, joint.name))
        torque = 0.0
        for name, mass, com in bodies:
            if name in moved:
                r = poses[name][:3, :3] @ com + poses[name][:3, 3] - origin
                if joint.type == "prismatic":
                    torque -= float(axis @ (mass * GRAVITY))
                else:
                    torque -= float(axis @ np.cross(r, mass * GRAVITY))
        out[joint.name] = torque
    return out


def reference_pose(robot: Robot) -> tuple[float, ...]:
    """The pose servo damping is tuned at: `home` if the spec has one, else zero."""
    poses = dict(robot.poses)
    return poses.get("home", tuple(0.0 for _ in robot.movable_joints))


def derive_actuators(robot: Robot) -> Robot:
    """Position servos for actuated joints: kp = effort_peak / 0.01 rad, kv for critical
    damping of (armature + axis inertia at the reference pose), force limit = drive peak;
    a spec's own kp/kv win."""
    q = reference_pose(robot)
    actuators = []
    for joint in robot.movable_joints:
        if not joint.actuated or joint.effort_peak is None:
            continue
        kp = joint.kp if joint.kp is not None else joint.effort_peak / SERVO_ERROR_RAD
        inertia = joint.armature + axis_inertia(robot, joint.name, q)
        kv = joint.kv if joint.kv is not None else 2.0 * float(np.sqrt(kp * inertia))
        force = joint.drive_peak_torque_at_joint or joint.effort_peak
        actuators.append(Actuator(joint.name, kp, kv, force))
    return replace(robot, actuators=tuple(actuators))
