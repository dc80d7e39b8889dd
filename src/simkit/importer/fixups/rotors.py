"""The estimated rotor inertia (armature) of each driven joint, bounded by what it moves.

A URDF carries no rotor inertia, but simkit's servo (kp = effort per 0.01 rad)
needs inertia to stay stable at the kit's 2 ms step. The estimate is `ARMATURE_PER_EFFORT`
x effort (a geared motor's reflected rotor inertia), but at most `ARMATURE_SHARE` x the
inertia about the joint's axis of everything it moves at home (mass for a prismatic joint),
so the rotor never swamps the joint's own inertia. Where that bound holds it lower, the
servo's stiffness is lowered with it to keep its frequency at `SERVO_OMEGA` (the frequency
the old rule bounded it to): kp = SERVO_OMEGA^2 x (axis inertia + armature), marked
estimated. Each joint's value is reported with the rule that gave it.
"""

from __future__ import annotations

import math

import numpy as np

from simkit.importer.draft import Draft
from simkit.model.kinematics import forward

#: kg m^2 per N m of effort (kg per N for prismatic): a geared motor's reflected rotor inertia
ARMATURE_PER_EFFORT = 1.0e-3
#: the armature is at most this share of the axis inertia of what the joint moves
ARMATURE_SHARE = 3.0
#: rad/s: the servo frequency a bounded armature keeps (sqrt(100 / 1e-3): the frequency
#: ARMATURE_PER_EFFORT gives simkit's servo; 0.63 rad per 2 ms step)
SERVO_OMEGA = math.sqrt(1.0e5)


def axis_inertias(robot, q) -> dict[str, float]:
    """Per movable joint: kg m^2 about a revolute joint's axis (kg for a prismatic one) of
    everything it moves at `q` (dynamics.axis_inertia's measure). Each link's mass, first and
    second moments (world frame, at the origin) are summed up the tree once, children before
    parents, and shifted to each joint's axis: linear in the links, not quadratic."""
    poses = forward(robot, q)
    sums: dict[str, list] = {}  # link -> [mass, sum m p, sum m p p^T, sum R I R^T]
    for link in robot.links:
        part = [0.0, np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3))]
        if link.inertial is not None and link.name in poses:
            rot, mass = poses[link.name][:3, :3], link.inertial.mass
            p = rot @ np.asarray(link.inertial.com) + poses[link.name][:3, 3]
            part = [mass, mass * p, mass * np.outer(p, p), rot @ link.inertial.tensor() @ rot.T]
        sums[link.name] = part
    for joint in reversed(robot.joints):  # joints list parents first: children summed first
        if joint.parent in sums and joint.child in sums:
            both = zip(sums[joint.parent], sums[joint.child], strict=True)
            sums[joint.parent] = [a + b for a, b in both]
    out = {}
    for joint in robot.movable_joints:
        mass, first, second, spin = sums[joint.child]
        if joint.type == "prismatic":
            out[joint.name] = float(mass)
            continue
        axis = poses[joint.child][:3, :3] @ np.asarray(joint.axis)
        o = poses[joint.child][:3, 3]
        r2 = np.trace(second) - 2 * o @ first + mass * (o @ o)  # sum m |p - o|^2
        along = axis @ second @ axis - 2 * (axis @ o) * (axis @ first) + mass * (axis @ o) ** 2
        out[joint.name] = float(axis @ spin @ axis + r2 - along)
    return out


def armature(draft: Draft) -> None:
    """Each driven joint's estimated armature (module doc), and the servo stiffness that
    keeps a bounded one stable; one report line per joint."""
    robot = draft.robot()
    home = dict(robot.poses).get("home")
    inertias = axis_inertias(robot, home)
    for spec in draft.movable():
        if "mimic" in spec or "armature" in spec:
            continue  # a follower has no servo of its own
        effort = float(spec["effort_peak"])
        own = inertias[spec["name"]]
        by_effort = float(f"{ARMATURE_PER_EFFORT * effort:.3g}")
        bound = float(f"{ARMATURE_SHARE * own:.3g}")
        where = draft.where("joint", spec["name"], "limit")
        unit = "kg" if spec["type"] == "prismatic" else "kg m^2"
        if by_effort <= bound or bound <= 0.0:
            spec["armature"] = by_effort
            why = (
                f"no armature in {draft.a_noun}: {by_effort:g} {unit} "
                f"({ARMATURE_PER_EFFORT:g} x effort, "
                f"a geared motor's reflected rotor inertia; within {ARMATURE_SHARE:g} x the "
                f"{own:.3g} {unit} it moves; keeps the servo stable on light links)"
            )
            spec["estimated"] = [*spec.get("estimated", []), "armature"]
        else:
            spec["armature"] = bound
            kp = float(f"{SERVO_OMEGA**2 * (own + bound):.3g}")
            spec["kp"] = kp
            why = (
                f"no armature in {draft.a_noun}: {bound:g} {unit}, {ARMATURE_SHARE:g} x the "
                f"{own:.3g} "
                f"{unit} the joint moves at home ({ARMATURE_PER_EFFORT:g} x effort, "
                f"{by_effort:g}, would swamp it); servo kp {kp:g} (not effort / 0.01 rad) so "
                f"that it stays at {SERVO_OMEGA:.0f} rad/s, stable at the kit's 2 ms step"
            )
            spec["estimated"] = [*spec.get("estimated", []), "armature", "kp"]
        draft.note(why, where)
    draft.changed()
