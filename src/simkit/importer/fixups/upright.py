"""Which way up a floating-base robot stands: the rotation of its floating joint at home.

A URDF's free joint is implicit, so the importer starts the base at the identity. Most
legged robots are drawn Z-up, their limbs hanging along -z; a few are drawn Y-up
(a biomechanics model of a human body: knees and ankles 0.44 m along -y, the spine along +y), and
at the identity they lie on their side and roll over. The limbs decide: from each branch
leaving the base frame, the farthest end of its movable chains (a foot, a hand, the head: the
CoM of the last link), summed in the base frame. Where that sum points along one axis
direction other than -z, and the links' CoMs spread at least twice as far along that axis as
along z (a robot lying
down, not a flat drone), the base is turned so that direction points down. Reported.
"""

from __future__ import annotations

import math

import numpy as np

from simkit.model.kinematics import forward

#: the axis direction the limbs point along -> floating joint rpy (rad) turning it to -z
DIRECTIONS = {
    "+x": (np.array([1.0, 0.0, 0.0]), (0.0, math.pi / 2, 0.0)),
    "-x": (np.array([-1.0, 0.0, 0.0]), (0.0, -math.pi / 2, 0.0)),
    "+y": (np.array([0.0, 1.0, 0.0]), (-math.pi / 2, 0.0, 0.0)),
    "-y": (np.array([0.0, -1.0, 0.0]), (math.pi / 2, 0.0, 0.0)),
    "+z": (np.array([0.0, 0.0, 1.0]), (math.pi, 0.0, 0.0)),
    "-z": (np.array([0.0, 0.0, -1.0]), (0.0, 0.0, 0.0)),
}
SPREAD = 2.0  # how much farther the joints spread along the limbs' axis than along z


def points(robot, poses: dict, base: str) -> dict[str, np.ndarray]:
    """Each link's CoM (its origin without an inertial) and each frame's origin, in the
    base frame (m): a limb's reach, not just its joints (a short hip joint, a long leg)."""
    inverse = np.linalg.inv(poses[base])
    com = {link.name: link.inertial.com for link in robot.links if link.inertial is not None}
    return {
        name: (inverse @ pose @ np.append(com.get(name, (0.0, 0.0, 0.0)), 1.0))[:3]
        for name, pose in poses.items()
    }


def limb_ends(robot, poses: dict, base: str) -> np.ndarray:
    """Sum (m, base frame) over the branches leaving the base's welded frame of the farthest
    child of a movable joint with no movable joint below it."""
    kids: dict[str, list] = {}
    for joint in robot.joints:
        kids.setdefault(joint.parent, []).append(joint)

    ends: dict[str, list[str]] = {}  # per link below the base, children first (no recursion:
    stack = [(base, False)]  # a chain of thousands of links)
    while stack:
        link, done = stack.pop()
        if not done:
            stack.append((link, True))
            stack.extend((joint.child, False) for joint in kids.get(link, []))
            continue
        out: list[str] = []
        for joint in kids.get(link, []):
            out += ends[joint.child] or ([joint.child] if joint.movable else [])
        ends[link] = out

    firsts, pending = [], list(reversed(kids.get(base, [])))  # depth first, in joint order
    while pending:
        joint = pending.pop()
        if joint.movable:
            firsts.append(joint)
        else:
            pending.extend(reversed(kids.get(joint.child, [])))

    at = points(robot, poses, base)
    total = np.zeros(3)
    for joint in firsts:
        names = ends[joint.child] or [joint.child]
        total += max((at[n] for n in names), key=lambda p: float(np.linalg.norm(p)))
    return total


def upright(robot, noun: str = "URDF") -> tuple[tuple[float, float, float], str] | None:
    """The floating joint's rpy (rad) that stands the robot on its limbs, and why; None where
    the identity does (the limbs hang along -z, or nothing tells)."""
    floating = robot.floating_joint
    if floating is None:
        return None
    poses = forward(robot, dict(robot.poses).get("home"))
    total = limb_ends(robot, poses, floating.child)
    name = max(DIRECTIONS, key=lambda k: float(DIRECTIONS[k][0] @ total))
    direction, rpy = DIRECTIONS[name]
    if name == "-z" or float(direction @ total) <= 0.0:
        return None
    reach = np.array(list(points(robot, poses, floating.child).values()))
    spread = reach.max(axis=0) - reach.min(axis=0)
    axis = int(np.argmax(np.abs(direction)))
    if spread[axis] < SPREAD * spread[2]:
        return None
    why = (
        f"floating base turned rpy {rpy[0]:.4g} {rpy[1]:.4g} {rpy[2]:.4g} rad: its limbs "
        f"(feet, hands, head) point along {name} in the {noun} ({spread[axis]:.3g} m of links "
        f"along it, {spread[2]:.3g} m along z); turned so that {name} points down"
    )
    return rpy, why
