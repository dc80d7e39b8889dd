"""Analytic inverse kinematics of a wrist-partitioned 6R arm, and the kit's IK reference cases.

The chain this solver accepts is the one the kit page describes ("Frames and conventions"):
every joint origin a pure translation, axes J1 z, J2 y, J3 y, J4 x, J5 y, J6 z (either sign),
and the last three axes meeting at the wrist centre (the J5 origin on the J4 axis, the J6
origin on the J6 axis). Offsets are general: a shoulder x-offset, lateral (y) offsets and
an elbow offset are all solved in closed form. Angles in rad, lengths in m, poses T_base_tool.

Solution steps: the wrist centre from the target; J1 from its position about the J1 axis
(shoulder front/back); J2/J3 as a planar two-link problem (elbow up/down); J4..J6 as x-y-z
Euler angles of the remaining rotation (wrist no-flip/flip); then every +-2 pi multiple that
the joint limits allow.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from simkit.model.kinematics import axis_angle, chain, rpy_matrix, transform
from simkit.model.robot import Robot

AXES = ("z", "y", "y", "x", "y", "z")
_UNIT = {"x": 0, "y": 1, "z": 2}
#: Branch flag definitions, written into ik_cases.json and robot.json `ik_reference`.
BRANCH_FLAGS = {
    "shoulder": "front: the wrist centre lies on the +x side of link_1's frame (the side the "
    "arm reaches at home); back: on the -x side (J1 turned half a turn, arm over the top)",
    "elbow": "up: J3 is above its stretched value (J3 - J3_stretched in (0, pi), as at home); "
    "down: below it",
    "wrist": "noflip: cos(J5) > 0, as at home; flip: cos(J5) < 0 (J4 and J6 half a turn "
    "round, J5 mirrored)",
}
METHOD = (
    "closed form for a wrist-partitioned 6R arm: wrist centre = tool0 target less the J6 "
    "offset; J1 from the wrist centre about the J1 axis (lateral offset allowed); J2, J3 as a "
    "planar two-link problem; J4, J5, J6 as x-y-z Euler angles of R_link3_link6; then every "
    "+-2 pi multiple inside the joint limits"
)


@dataclass(frozen=True, eq=False)
class ArmChain:
    """A 6R wrist-partitioned chain from `base` (J1's parent) to `tool` (a frame on link 6).

    `origins` are the joints' translations (m, parent frame), `axes` their unit axes,
    `signs` the sign of each axis along its principal direction, `T_6_tool` the tool frame.
    """

    base: str
    tool: str
    names: tuple[str, ...]
    parents: tuple[str, ...]
    children: tuple[str, ...]
    origins: np.ndarray
    axes: np.ndarray
    signs: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    T_6_tool: np.ndarray
    tool_xyz: tuple[float, float, float]
    tool_rpy: tuple[float, float, float]

    def fk(self, q) -> np.ndarray:
        """T_base_tool at joint angles q (rad)."""
        out = np.eye(4)
        for origin, axis, value in zip(self.origins, self.axes, q, strict=True):
            out = out @ transform(origin, axis_angle(axis, value))
        return out @ self.T_6_tool

    def frames(self, q) -> list[np.ndarray]:
        """T_base_link_i for i = 1..6 (each joint's child frame) at q."""
        out, T = [], np.eye(4)
        for origin, axis, value in zip(self.origins, self.axes, q, strict=True):
            T = T @ transform(origin, axis_angle(axis, value))
            out.append(T)
        return out

    def within_limits(self, q, tol: float = 1e-9) -> bool:
        q = np.asarray(q)
        return bool(np.all(q >= self.lower - tol) and np.all(q <= self.upper + tol))


@dataclass(frozen=True)
class Solution:
    """One IK solution (rad) with its branch flags."""

    q: tuple[float, ...]
    shoulder: str
    elbow: str
    wrist: str

    def as_json(self) -> dict:
        return {
            "q": list(self.q),
            "shoulder": self.shoulder,
            "elbow": self.elbow,
            "wrist": self.wrist,
        }


def arm_chain(robot: Robot) -> ArmChain | None:
    """The robot's wrist-partitioned 6R chain, or None when the spec describes anything else
    (a legged robot, a 2R arm, a chain with rotated joint origins...)."""
    if not robot.wrist_centre or not robot.tool_frame:
        return None
    frames = {f.name: f for f in robot.frames}
    tool = frames.get(robot.tool_frame)
    movable = robot.movable_joints
    if tool is None or len(movable) != 6:
        return None
    base = movable[0].parent
    try:
        joints = chain(robot, base, tool.parent)
    except ValueError:
        return None
    if [j.name for j in joints] != [j.name for j in movable]:
        return None
    if any(j.type != "revolute" or j.lower is None or j.upper is None for j in joints):
        return None
    if any(np.abs(j.rpy).max() > 1e-12 for j in joints):
        return None
    signs = []
    for joint, name in zip(joints, AXES, strict=True):
        axis = np.asarray(joint.axis, dtype=float)
        k = _UNIT[name]
        if abs(abs(axis[k]) - 1.0) > 1e-12:
            return None
        signs.append(float(np.sign(axis[k])))
    origins = np.array([j.xyz for j in joints], dtype=float)
    # Wrist partition: the J5 origin on the J4 axis (x), the J6 origin on the J6 axis (z),
    # and the named wrist centre is the J5 child (link_5).
    if np.abs(origins[4, 1:]).max() > 1e-12 or np.abs(origins[5, :2]).max() > 1e-12:
        return None
    if robot.wrist_centre != joints[4].child:
        return None
    return ArmChain(
        base=base,
        tool=tool.name,
        names=tuple(j.name for j in joints),
        parents=tuple(j.parent for j in joints),
        children=tuple(j.child for j in joints),
        origins=origins,
        axes=np.array([j.axis for j in joints], dtype=float),
        signs=np.array(signs),
        lower=np.array([j.lower for j in joints]),
        upper=np.array([j.upper for j in joints]),
        T_6_tool=transform(tool.xyz, rpy_matrix(tool.rpy)),
        tool_xyz=tool.xyz,
        tool_rpy=tool.rpy,
    )


def _wrap(angle: float) -> float:
    """Angle in (-pi, pi]."""
    out = (angle + np.pi) % (2 * np.pi) - np.pi
    return float(np.pi if out == -np.pi else out)


def _rot(axis: str, angle: float) -> np.ndarray:
    return axis_angle(np.eye(3)[_UNIT[axis]], angle)


def _euler_xyz(m: np.ndarray, flip: bool, hint: float) -> tuple[float, float, float]:
    """(a, b, c) with Rx(a) Ry(b) Rz(c) = m, cos(b) >= 0 unless `flip`. At the singularity
    (cos b = 0) a = hint and c takes the rest."""
    cb = np.hypot(m[0, 0], m[0, 1]) * (-1.0 if flip else 1.0)
    b = float(np.arctan2(m[0, 2], cb))
    if abs(cb) > 1e-10:
        a = float(np.arctan2(-m[1, 2] / cb, m[2, 2] / cb))
        c = float(np.arctan2(-m[0, 1] / cb, m[0, 0] / cb))
        return a, b, c
    a = hint
    both = float(np.arctan2(m[1, 0], m[1, 1]))  # a + c (b = +90 deg) or c - a (b = -90 deg)
    return a, b, (both - a) if m[0, 2] > 0 else (both + a)


def principal_solutions(arm: ArmChain, T_target: np.ndarray, hint4: float) -> list[Solution]:
    """The (up to) eight solutions with every angle in (-pi, pi]."""
    T6 = T_target @ np.linalg.inv(arm.T_6_tool)
    t = arm.origins
    wrist = T6[:3, 3] - T6[:3, :3] @ t[5]
    rel = wrist - t[0]
    c = t[3] + t[4]  # wrist centre in link_3's frame: J4 turns about the line through it
    lateral = t[1, 1] + t[2, 1] + c[1]
    r2 = rel[0] ** 2 + rel[1] ** 2
    if r2 < lateral**2:
        return []
    out: list[Solution] = []
    s = arm.signs
    for shoulder in ("front", "back"):
        px = np.sqrt(r2 - lateral**2) * (1.0 if shoulder == "front" else -1.0)
        th1 = float(np.arctan2(rel[1], rel[0]) - np.arctan2(lateral, px))
        ax, az = px - t[1, 0], rel[2] - t[1, 2]
        A = t[2, 0] * c[0] + t[2, 2] * c[2]
        B = t[2, 0] * c[2] - t[2, 2] * c[0]
        K = (ax**2 + az**2 - t[2, 0] ** 2 - t[2, 2] ** 2 - c[0] ** 2 - c[2] ** 2) / 2
        rho = np.hypot(A, B)
        if rho < 1e-12 or abs(K) > rho * (1 + 1e-12):
            continue
        stretched = float(np.arctan2(B, A))
        spread = float(np.arccos(np.clip(K / rho, -1.0, 1.0)))
        for elbow in ("up", "down"):
            th3 = stretched + (spread if elbow == "up" else -spread)
            vx = t[2, 0] + c[0] * np.cos(th3) + c[2] * np.sin(th3)
            vz = t[2, 2] - c[0] * np.sin(th3) + c[2] * np.cos(th3)
            th2 = float(np.arctan2(ax, az) - np.arctan2(vx, vz))
            R03 = _rot("z", th1) @ _rot("y", th2 + th3)
            R36 = R03.T @ T6[:3, :3]
            for wrist_flag in ("noflip", "flip"):
                th4, th5, th6 = _euler_xyz(R36, wrist_flag == "flip", hint4 * s[3])
                theta = np.array([th1, th2, th3, th4, th5, th6])
                q = tuple(_wrap(v) for v in theta * s)
                out.append(Solution(q, shoulder, elbow, wrist_flag))
    return out


def _multiples(arm: ArmChain, q: tuple[float, ...]) -> list[tuple[float, ...]]:
    """Every combination of q_i + 2 pi k_i inside the joint limits."""
    options = []
    for value, lo, hi in zip(q, arm.lower, arm.upper, strict=True):
        k_lo = int(np.ceil((lo - 1e-9 - value) / (2 * np.pi)))
        k_hi = int(np.floor((hi + 1e-9 - value) / (2 * np.pi)))
        opts = [float(np.clip(value + 2 * np.pi * k, lo, hi)) for k in range(k_lo, k_hi + 1)]
        if not opts:
            return []
        options.append(opts)
    return [tuple(combo) for combo in itertools.product(*options)]


def pose_error(a: np.ndarray, b: np.ndarray) -> float:
    """Largest element-wise difference of two poses' positions (m) and rotations."""
    return float(max(np.abs(a[:3, 3] - b[:3, 3]).max(), np.abs(a[:3, :3] - b[:3, :3]).max()))


def solve(
    arm: ArmChain, T_target: np.ndarray, hint4: float = 0.0, tol: float = 1e-9
) -> list[Solution]:
    """Every IK solution inside the joint limits for T_base_tool = T_target, branch flags
    attached, sorted by (shoulder, elbow, wrist, q). Each is verified by FK to `tol`."""
    out: list[Solution] = []
    for base in principal_solutions(arm, T_target, hint4):
        if pose_error(arm.fk(base.q), T_target) > tol:
            continue
        for q in _multiples(arm, base.q):
            if not any(np.abs(np.subtract(q, o.q)).max() < 1e-9 for o in out):
                out.append(Solution(q, base.shoulder, base.elbow, base.wrist))
    return sorted(out, key=lambda s: (s.shoulder, s.elbow, s.wrist, s.q))


def nearest(solutions: list[Solution], q_ref) -> Solution | None:
    """The solution closest to q_ref (largest joint difference), or None."""
    if not solutions:
        return None
    ref = np.asarray(q_ref)
    return min(solutions, key=lambda s: (float(np.abs(np.subtract(s.q, ref)).max()), s.q))


def branch_flags(arm: ArmChain, q) -> tuple[str, str, str]:
    """(shoulder, elbow, wrist) of the configuration q, by the definitions in BRANCH_FLAGS."""
    T = arm.fk(q)
    for sol in principal_solutions(arm, T, float(q[3])):
        if all(abs(_wrap(a - b)) < 1e-6 for a, b in zip(sol.q, q, strict=True)):
            return sol.shoulder, sol.elbow, sol.wrist
    raise ValueError("configuration is singular: its branch is not defined")
