"""Derive step: FK reference poses (wrist centre, tool pose in the first link's frame) at every
named pose, and the geometric reach at the stretched pose (kit page 000_5f76ade803e16979.txt,
"Published numbers")."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from simkit.model.kinematics import forward
from simkit.model.robot import Robot


def _distance_from_axis(point: np.ndarray, origin: np.ndarray, axis: np.ndarray) -> float:
    r = point - origin
    return float(np.linalg.norm(r - axis * (axis @ r)))


def _tool_chain_first(robot: Robot) -> list:
    """Movable joints, the first on the tool frame's chain first: the base frame is that
    joint's parent, which every FK from base to tool passes (a joint listed earlier may sit
    on another branch, such as a pan joint on a pedestal beside the arm)."""
    movable = list(robot.movable_joints)
    parent_joint = {j.child: j for j in robot.joints}
    frame_parent = {f.name: f.parent for f in robot.frames}
    node = frame_parent.get(robot.tool_frame, robot.tool_frame)
    chain: list = []
    while node in parent_joint and len(chain) <= len(robot.joints):
        chain.append(parent_joint[node])
        node = chain[-1].parent
    on_chain = [j for j in reversed(chain) if j.movable]
    return on_chain[:1] + [j for j in movable if j not in on_chain[:1]]


def derive_references(robot: Robot) -> Robot:
    """FK reference poses (wrist centre, tool pose in the first link's frame) and reach."""
    movable = _tool_chain_first(robot)
    base = movable[0].parent if movable else robot.root
    tool = robot.tool_frame
    fk_reference = []
    for name, q in robot.poses:
        poses = forward(robot, q)
        inv = np.linalg.inv(poses[base])
        entry: dict = {"pose": name, "q": list(q)}
        if robot.wrist_centre:
            entry["wrist_centre"] = list((inv @ poses[robot.wrist_centre])[:3, 3])
        if tool:
            t = inv @ poses[tool]
            entry[tool] = {"xyz": list(t[:3, 3]), "rotation": t[:3, :3].tolist()}
        fk_reference.append(entry)
    reach = None
    if "stretched" in dict(robot.poses) and movable and robot.wrist_centre and tool:
        poses = forward(robot, robot.pose("stretched"))
        first = poses[movable[0].child]
        origin, axis = first[:3, 3], first[:3, :3] @ np.asarray(movable[0].axis)
        reach = {
            "wrist": _distance_from_axis(poses[robot.wrist_centre][:3, 3], origin, axis),
            "flange": _distance_from_axis(poses[tool][:3, 3], origin, axis),
        }
    products = replace(
        robot.products, fk_reference=fk_reference, base_frame=base, reach_geometric=reach
    )
    return replace(robot, products=products)
