"""The benchmark pick-and-place cycle: path, joint-space trapezoids, 1 ms samples, and the
inverse-dynamics check on the kit's MJCF.

Source: 000_5f76ade803e16979.txt, "Benchmark cycle". The tool points straight down and keeps
its heading; pick A and place B are 305 mm apart along y, centred 350 mm from the J1 axis on
+x; the TCP (50 mm out from the flange) lifts 25 mm at each: A low, A high, B high, B low and
back. Six rest-to-rest joint-space moves; every joint follows a trapezoid at its benchmark
acceleration (80 % of its peak-torque acceleration at the cycle poses, drive model), and a
segment takes the slowest joint's time at max_velocity. SI units, base_link frame.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from simkit.derive import motion
from simkit.kitio import layout
from simkit.model import ik
from simkit.model.robot import Robot

DT = 0.001  # s, sample period of the trajectory files (kit page)
SEPARATION = 0.305  # m, A to B along y
CENTRE_X = 0.350  # m from the J1 axis on +x
LIFT = 0.025  # m
TCP_OFFSET = 0.050  # m out from the flange face along the tool axis
DEFAULT_LOW_HEIGHT = 0.050  # m above base_link (Rosie 600 and 1000); the spec may override
ACCELERATION_FRACTION = 0.8
#: Tool pointing straight down, heading kept: tool0 x along base +x, z along base -z (tool0's
#: orientation at home on the Rosie arms).
TOOL_ROTATION = np.diag([1.0, -1.0, -1.0])
POINTS = ("A_low", "A_high", "B_high", "B_low")
SEQUENCE = ("A_low", "A_high", "B_high", "B_low", "B_high", "A_high", "A_low")


@dataclass(frozen=True, eq=False)
class Cycle:
    """One sampled cycle. Arrays: t (n,), q/qd/qdd (n, 6) rad, rad/s, rad/s^2, tcp (n, 3) m."""

    name: str
    payload: float
    acceleration: np.ndarray
    waypoints: np.ndarray
    segment_times: tuple[float, ...]
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tcp: np.ndarray


def low_height(robot: Robot) -> float:
    """Height (m) of the low points above base_link: the spec's published value or 50 mm."""
    return float(robot.published.get("benchmark_low_height", DEFAULT_LOW_HEIGHT))


def tcp_points(robot: Robot) -> dict[str, list[float]]:
    """The four TCP points (m, base_link); A on -y, B on +y."""
    low = low_height(robot)
    out = {}
    for name in POINTS:
        y = -SEPARATION / 2 if name.startswith("A") else SEPARATION / 2
        out[name] = [CENTRE_X, y, low + (LIFT if name.endswith("high") else 0.0)]
    return out


def tool_target(tcp: list[float]) -> np.ndarray:
    """T_base_tool0 that puts the TCP at `tcp` with the tool pointing down."""
    T = np.eye(4)
    T[:3, :3] = TOOL_ROTATION
    T[:3, 3] = np.asarray(tcp) - TOOL_ROTATION @ np.array([0.0, 0.0, TCP_OFFSET])
    return T


def waypoint_poses(robot: Robot, arm: ik.ArmChain) -> np.ndarray:
    """Joint poses along SEQUENCE: the first the IK solution nearest home, each next the one
    nearest the previous point's pose."""
    points = tcp_points(robot)
    ref = np.asarray(dict(robot.poses).get("home", np.zeros(6)))
    poses: dict[str, np.ndarray] = {}
    for name in POINTS:
        sol = ik.nearest(ik.solve(arm, tool_target(points[name])), ref)
        if sol is None:
            raise ValueError(f"benchmark point {name} {points[name]} is out of reach")
        poses[name] = ref = np.asarray(sol.q)
    return np.array([poses[name] for name in SEQUENCE])


def trapezoid_time(distance: float, accel: float, vmax: float) -> float:
    """Shortest rest-to-rest time (s) over `distance` with |qdd| = accel, |qd| <= vmax."""
    if distance <= vmax**2 / accel:
        return 2.0 * math.sqrt(distance / accel)
    return distance / vmax + vmax / accel


def cruise_speed(distance: float, accel: float, duration: float) -> float:
    """Cruise speed of a trapezoid at `accel` that covers `distance` in exactly `duration`."""
    disc = max(accel**2 * duration**2 - 4.0 * accel * distance, 0.0)
    return (accel * duration - math.sqrt(disc)) / 2.0


def _segment(q0, q1, accel, vmax, tau, duration):
    """Position, velocity and acceleration at local times tau (right-continuous)."""
    n = len(tau)
    q, qd, qdd = np.empty((n, 6)), np.empty((n, 6)), np.empty((n, 6))
    for j in range(6):
        dist, sign = abs(q1[j] - q0[j]), np.sign(q1[j] - q0[j])
        v = cruise_speed(dist, accel[j], duration) if dist > 0 else 0.0
        ramp = v / accel[j]
        back = np.clip(duration - tau, 0.0, None)
        pos = np.where(
            tau < ramp,
            0.5 * accel[j] * tau**2,
            np.where(
                tau < duration - ramp,
                0.5 * accel[j] * ramp**2 + v * (tau - ramp),
                dist - 0.5 * accel[j] * back**2,
            ),
        )
        cruise = np.where(tau < duration - ramp, v, accel[j] * back)
        vel = np.where(tau < ramp, accel[j] * tau, cruise)
        acc = np.where(tau < ramp, accel[j], np.where(tau < duration - ramp, 0.0, -accel[j]))
        q[:, j] = q0[j] + sign * pos
        qd[:, j], qdd[:, j] = sign * vel, sign * acc
    return q, qd, qdd


def cycle(robot: Robot, arm: ik.ArmChain, name: str, payload: float) -> Cycle:
    """The cycle with `payload` kg: accelerations, segment times (whole ms) and samples."""
    waypoints = waypoint_poses(robot, arm)
    acc = (
        np.min(
            [motion.peak_accelerations(robot, arm, q, payload, drive=True) for q in waypoints],
            axis=0,
        )
        * ACCELERATION_FRACTION
    )
    vmax = np.array([robot.joint(n).max_velocity for n in arm.names])
    steps = []
    for q0, q1 in itertools.pairwise(waypoints):
        slowest = max(
            trapezoid_time(abs(b - a), ac, v) for a, b, ac, v in zip(q0, q1, acc, vmax, strict=True)
        )
        steps.append(math.ceil(slowest / DT - 1e-9))  # segment ends on a sample
    chunks = []
    for (q0, q1), n in zip(itertools.pairwise(waypoints), steps, strict=True):
        chunks.append(_segment(q0, q1, acc, vmax, np.arange(n) * DT, n * DT))
    end = (waypoints[-1][None, :], np.zeros((1, 6)), np.zeros((1, 6)))
    q, qd, qdd = (np.vstack([c[i] for c in chunks] + [end[i]]) for i in range(3))
    tcp_local = np.array([0.0, 0.0, TCP_OFFSET, 1.0])
    tcp = np.array([(arm.fk(row) @ tcp_local)[:3] for row in q])
    t = np.arange(len(q)) * DT
    return Cycle(name, payload, acc, waypoints, tuple(n * DT for n in steps), t, q, qd, qdd, tcp)


def payload_on_link(arm: ik.ArmChain, mass: float) -> dict:
    """The payload model plus its CoM in link 6's frame (for attaching it in MuJoCo)."""
    out = motion.payload_model(mass, arm.tool)
    out["link"] = arm.children[5]
    out["com_link"] = list(motion.payload_body(arm, mass)[2])
    return out


def benchmarks_block(robot: Robot, arm: ik.ArmChain, cycles: list[Cycle]) -> dict:
    """robot.json `benchmarks`; `kit_model_check` and `rated_cycle_torque` are filled by the
    simulate stage (MuJoCo inverse dynamics on the written MJCF)."""
    names = list(arm.names)
    return {
        "path": {
            "description": "tool straight down, heading kept; pick A and place B "
            f"{SEPARATION * 1000:g} mm apart along y, centred {CENTRE_X * 1000:g} mm from the J1 "
            f"axis on +x; {LIFT * 1000:g} mm lifts: A low, A high, B high, B low, then back",
            "tool_rotation_base_link": TOOL_ROTATION.tolist(),
            "low_height_above_base_link": low_height(robot),
            "tcp_points_base_link_m": tcp_points(robot),
            "sequence": list(SEQUENCE),
            "joint_poses": {
                "joints": names,
                "q": [list(q) for q in cycles[0].waypoints[: len(POINTS)]],
            },
        },
        "tcp": {"frame": arm.tool, "xyz": [0.0, 0.0, TCP_OFFSET]},
        "payload": {c.name: payload_on_link(arm, c.payload) for c in cycles},
        "profile": "six rest-to-rest joint-space moves, no blending, dwell or gripper time; every "
        "joint a trapezoid at its benchmark acceleration (cruise speed reduced so all joints "
        "finish together); each segment takes the slowest joint's time at max_velocity, "
        f"rounded up to the {DT * 1000:g} ms sample grid",
        "acceleration": {
            "joints": names,
            "rule": f"{ACCELERATION_FRACTION:g} x the joint's peak-torque acceleration at the "
            "cycle poses (lowest over them), with the cycle's payload; " + motion.DRIVE_METHOD,
            **{
                c.name: {
                    "rad_s2": list(c.acceleration),
                    "deg_s2": [math.degrees(a) for a in c.acceleration],
                }
                for c in cycles
            },
        },
        "segment_times": {c.name: list(c.segment_times) for c in cycles},
        "cycle_time": {c.name: float(sum(c.segment_times)) for c in cycles},
        "trajectory_files": {
            "cycle_1kg": {
                "csv": layout.benchmark(robot.name, "csv"),
                "json": layout.benchmark(robot.name, "json"),
                "dt": DT,
            }
        },
        # kit page: the most torque each joint of the kit's MuJoCo model needs to follow the
        # trajectory (the 1 kg files), as a fraction of its force limit: simulate/benchmark.py
        "kit_model_check": None,
        "rated_cycle_torque": None,
        "notes": [
            "cycle times are computed by this model; the reference page does not give the "
            "published cycle times",
            f"rated payload {motion.rated_payload(robot):g} kg"
            + (" (an estimate)" if "payload" in robot.published_estimated else ""),
            "link masses and drive data marked `estimated` in robot.json feed the "
            "accelerations; their sum matches the published robot mass",
        ],
    }


def trajectory_data(robot: Robot, arm: ik.ArmChain, c: Cycle) -> dict:
    """What the benchmark emitter writes: columns and the arrays (read-only)."""
    for arr in (c.t, c.q, c.qd, c.qdd, c.tcp):
        arr.setflags(write=False)
    bounds = np.cumsum((0.0, *c.segment_times))
    segments = [
        {"from": a, "to": b, "t_start": float(s), "t_end": float(e)}
        for a, b, s, e in zip(SEQUENCE[:-1], SEQUENCE[1:], bounds[:-1], bounds[1:], strict=True)
    ]
    return {
        "robot": robot.name,
        "cycle": c.name,
        "payload_kg": c.payload,
        "dt": DT,
        "joints": list(arm.names),
        "segments": segments,
        "t": c.t,
        "q": c.q,
        "qd": c.qd,
        "qdd": c.qdd,
        "tcp": c.tcp,
    }
