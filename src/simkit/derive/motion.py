"""Peak-torque accelerations and robot.json's `motion` block, for wrist-partitioned 6R arms.

Source: 000_5f76ade803e16979.txt, "Accelerations and motion profiles". A joint's
derived_max_acceleration is its acceleration from standstill at peak torque with every other
joint held: (effort_peak - |gravity torque|) / (armature + inertia about the joint axis of
everything it moves), at the stretched pose with the rated payload (and, in
`motion.derived_max_acceleration`, at the work pose with 1 kg). Units: rad/s^2 and deg/s^2.
"""

from __future__ import annotations

import math

import numpy as np

from simkit.model import dynamics
from simkit.model.ik import ArmChain
from simkit.model.robot import Robot

#: Benchmark payload model (kit page, "Benchmark cycle", Payload): everything on the flange as
#: one body, CoM 100 mm out along the tool axis and 50 mm off it (here along tool0 +x), with
#: the inertia of a uniform 100 mm cube. The derived accelerations use the same payload model.
PAYLOAD_COM_TOOL = (0.05, 0.0, 0.10)
PAYLOAD_CUBE_EDGE = 0.10
WORK_PAYLOAD = 1.0  # kg: motion.derived_max_acceleration at the work pose (kit page)
#: RosieOS's planner bounds jerk at 2 x the acceleration setting / 0.2 s (kit page).
JERK_FACTOR = 2.0
JERK_TIME = 0.2
METHOD = (
    "(effort_peak - |gravity torque|) / (armature + inertia about the joint axis of everything "
    "the joint moves, payload included), from standstill with the other joints held; rigid "
    "bodies from robot.json links, gravity 9.81 m/s^2 along -z of base_link"
)
DRIVE_METHOD = (
    "drive model: min((drive_peak_torque_at_joint - |gravity torque|) / (armature + inertia), "
    "(effort_peak - |gravity torque|) / inertia): the motor accelerates its rotor (armature) "
    "ahead of the gearbox, and the gearbox passes at most effort_peak to the arm"
)


def payload_model(mass: float, frame: str = "tool0") -> dict:
    """The payload as robot.json describes it (in the tool frame `frame`, SI)."""
    moment = mass * 2 * PAYLOAD_CUBE_EDGE**2 / 12
    return {
        "mass": mass,
        "frame": frame,
        "com_xyz": list(PAYLOAD_COM_TOOL),
        "inertia_diag": [moment, moment, moment],
        "inertia_model": f"uniform cube, edge {PAYLOAD_CUBE_EDGE:g} m, about its CoM",
    }


def payload_body(arm: ArmChain, mass: float) -> tuple[str, float, np.ndarray, np.ndarray]:
    """The payload as a `dynamics` extra body on link 6: (link, mass, com (m), tensor)."""
    com = (arm.T_6_tool @ np.array([*PAYLOAD_COM_TOOL, 1.0]))[:3]
    moment = mass * 2 * PAYLOAD_CUBE_EDGE**2 / 12  # a cube's tensor is isotropic
    return arm.children[5], mass, com, np.eye(3) * moment


def joint_terms(robot: Robot, arm: ArmChain, q, mass: float) -> tuple[np.ndarray, np.ndarray]:
    """(|gravity torque| (N m), axis inertia without armature (kg m^2)) per chain joint."""
    extra = [payload_body(arm, mass)] if mass > 0 else []
    gravity = dynamics.gravity_torques(robot, q, extra)
    g = np.array([abs(gravity[name]) for name in arm.names])
    inertia = np.array([dynamics.axis_inertia(robot, name, q, extra) for name in arm.names])
    return g, inertia


def peak_accelerations(
    robot: Robot, arm: ArmChain, q, mass: float, drive: bool = False
) -> np.ndarray:
    """Peak-torque acceleration (rad/s^2) per chain joint at pose q with `mass` kg on the
    flange; `drive` uses the drive model (DRIVE_METHOD) instead of effort_peak alone."""
    g, inertia = joint_terms(robot, arm, q, mass)
    joints = [robot.joint(n) for n in arm.names]
    effort = np.array([j.effort_peak for j in joints])
    armature = np.array([j.armature for j in joints])
    out = (effort - g) / (armature + inertia)
    if drive:
        peak = np.array([j.drive_peak_torque_at_joint or j.effort_peak for j in joints])
        out = np.minimum((peak - g) / (armature + inertia), (effort - g) / inertia)
    return out


def _deg(values) -> list[float]:
    return [math.degrees(v) for v in values]


def _case(robot: Robot, arm: ArmChain, pose: str, mass: float) -> dict:
    q = robot.pose(pose)
    g, inertia = joint_terms(robot, arm, q, mass)
    acc = peak_accelerations(robot, arm, q, mass)
    return {
        "pose": pose,
        "q": list(q),
        "payload_kg": mass,
        "payload": payload_model(mass, arm.tool),
        "rad_s2": list(acc),
        "deg_s2": _deg(acc),
        "gravity_torque": list(g),
        "axis_inertia": list(inertia),
        "armature": [robot.joint(n).armature for n in arm.names],
    }


def rated_payload(robot: Robot) -> float:
    """The rated payload (kg) from the spec's published block; 0 when it gives none."""
    return float(robot.published.get("payload", 0.0))


def motion_block(robot: Robot, arm: ArmChain) -> tuple[dict, dict]:
    """(robot.json `motion`, per-joint robot.json additions) for a 6R arm."""
    rated = rated_payload(robot)
    stretched = _case(robot, arm, "stretched", rated)
    work = _case(robot, arm, "work", WORK_PAYLOAD)
    jerk = [JERK_FACTOR * a / JERK_TIME for a in stretched["rad_s2"]]
    per_joint = {
        name: {"derived_max_acceleration": a, "derived_max_acceleration_deg_s2": math.degrees(a)}
        for name, a in zip(arm.names, stretched["rad_s2"], strict=True)
    }
    block = {
        "profiles": {
            "programs": {
                "type": "joint-space cubic spline",
                "free_space": "clamped cubic B-spline (continuous acceleration)",
                "welds": "cubic Hermite curves",
                "limits": "planned within the velocity and acceleration settings and played as "
                "planned",
            },
            "jog_stop_move_to": {
                "type": "double-S (jerk-limited)",
                "jerk": "the cell's machine jog jerk where one is set",
            },
            "benchmark": {
                "type": "trapezoid",
                "note": "rest to rest, no blending; each joint at its benchmark acceleration "
                "(benchmarks.acceleration)",
            },
        },
        "acceleration": {
            "joints": list(arm.names),
            "limit": stretched["rad_s2"],
            "limit_deg_s2": stretched["deg_s2"],
            "source": "joints[].derived_max_acceleration (stretched pose, rated payload)",
        },
        "jerk": {
            "per_joint_limit": None,
            "planner_bound_rule": f"{JERK_FACTOR:g} x acceleration setting / {JERK_TIME:g} s",
            "planner_bound_at_limit": jerk,
            "planner_bound_at_limit_deg_s3": _deg(jerk),
            "note": "no per-joint jerk limit is stated; jog, stop ramps and Move-to are "
            "jerk-limited by the cell's machine jog jerk where one is set",
        },
        "derived_max_acceleration": {
            "method": METHOD,
            "joints": list(arm.names),
            "payload_model": payload_model(rated, arm.tool),
            "stretched_rated_payload": stretched,
            "work_1kg": work,
            "note": "conservative: effort_peak is the torque the gearbox passes to the arm, "
            "while the motor accelerates its own rotor ahead of the gearbox with its own "
            "torque, up to drive_peak_torque_at_joint",
        },
        "rosieos_settings": None,
        "rosieos_settings_note": "no RosieOS planning settings are published for this robot",
    }
    return block, per_joint
