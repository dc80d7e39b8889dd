"""Kinematics: tree order, T_parent_child, forward kinematics and reach. Pure numpy.

Conventions: URDF's fixed-axis roll-pitch-yaw (R = Rz(yaw) Ry(pitch) Rx(roll)); a revolute
joint rotates its child about `axis` (expressed in the child frame at q = 0) after the origin
transform, exactly as URDF defines it.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence

import numpy as np

from simkit.model.robot import Joint, Robot
from simkit.spec.schema import depth_first


def rpy_matrix(rpy: Sequence[float]) -> np.ndarray:
    """Rotation matrix of URDF roll-pitch-yaw (rad)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def matrix_rpy(rot: np.ndarray) -> tuple[float, float, float]:
    """URDF roll-pitch-yaw (rad) of a rotation matrix."""
    pitch = float(np.arctan2(-rot[2, 0], np.hypot(rot[0, 0], rot[1, 0])))
    if abs(abs(pitch) - np.pi / 2) < 1e-9:
        roll = 0.0
        yaw = float(np.arctan2(-rot[0, 1], rot[1, 1]))
    else:
        roll = float(np.arctan2(rot[2, 1], rot[2, 2]))
        yaw = float(np.arctan2(rot[1, 0], rot[0, 0]))
    return roll, pitch, yaw


def axis_angle(axis: Sequence[float], angle: float) -> np.ndarray:
    """Rotation by `angle` (rad) about unit `axis` (Rodrigues), as the kit page's rot()."""
    x, y, z = axis
    c, s, t = np.cos(angle), np.sin(angle), 1 - np.cos(angle)
    return np.array(
        [
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
    )


def transform(xyz: Sequence[float], rot: np.ndarray | None = None) -> np.ndarray:
    """4x4 homogeneous transform from a translation and a rotation matrix."""
    out = np.eye(4)
    out[:3, 3] = xyz
    if rot is not None:
        out[:3, :3] = rot
    return out


def quat_wxyz(rot: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion (w, x, y, z) of a rotation matrix, with w >= 0."""
    m = rot
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = np.sqrt(tr + 1.0) * 2
        q = (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = ((m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s)
    elif m[1, 1] > m[2, 2]:
        s = np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = ((m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s)
    else:
        s = np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = ((m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s)
    arr = np.array(q, dtype=float)
    arr /= np.linalg.norm(arr)
    if arr[0] < 0:
        arr = -arr
    return tuple(float(v) for v in arr)  # type: ignore[return-value]


def quat_matrix(quat: Sequence[float]) -> np.ndarray:
    """Rotation matrix of a quaternion (w, x, y, z); normalised first, so readers of float32
    files (glTF, USD) get an orthonormal matrix."""
    w, x, y, z = np.asarray(quat, dtype=float) / np.linalg.norm(quat)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def joint_origin(joint: Joint) -> np.ndarray:
    """T_parent_child of a joint at q = 0."""
    return transform(joint.xyz, rpy_matrix(joint.rpy))


def joint_motion(joint: Joint, q: float) -> np.ndarray:
    """The joint's own motion at position q (rad or m), applied after its origin."""
    if joint.type in ("revolute", "continuous"):
        return transform((0.0, 0.0, 0.0), axis_angle(joint.axis, q))
    if joint.type == "prismatic":
        return transform(np.asarray(joint.axis) * q)
    return np.eye(4)


def q_map(robot: Robot, q: Sequence[float] | dict[str, float] | None) -> dict[str, float]:
    """Joint positions by name; a sequence follows `robot.movable_joints` order."""
    if q is None:
        return {}
    if isinstance(q, dict):
        return dict(q)
    names = [j.name for j in robot.movable_joints]
    if len(q) != len(names):
        raise ValueError(f"expected {len(names)} joint values, got {len(q)}")
    return dict(zip(names, (float(v) for v in q), strict=True))


def forward(robot: Robot, q=None) -> dict[str, np.ndarray]:
    """T_root_X for the root, every link and every frame, at joint positions q."""
    values = q_map(robot, q)
    poses: dict[str, np.ndarray] = {robot.root: np.eye(4)}
    for joint in robot.joints:
        poses[joint.child] = (
            poses[joint.parent]
            @ joint_origin(joint)
            @ joint_motion(joint, values.get(joint.name, 0.0))
        )
    for frame in robot.frames:
        poses[frame.name] = poses[frame.parent] @ transform(frame.xyz, rpy_matrix(frame.rpy))
    return poses


def pose_in(robot: Robot, q, target: str, base: str) -> np.ndarray:
    """T_base_target at joint positions q."""
    poses = forward(robot, q)
    return np.linalg.inv(poses[base]) @ poses[target]


def tree_order(joints: Sequence[Joint], root: str) -> list[Joint]:
    """Joints in depth-first order (`spec.schema.depth_first`): the model's joint order."""
    return depth_first(joints, root)


def chain(robot: Robot, base: str, tip: str) -> list[Joint]:
    """The joints from `base` down to link `tip`, in order."""
    parent_joint = {j.child: j for j in robot.joints}
    out: list[Joint] = []
    node = tip
    while node != base:
        joint = parent_joint.get(node)
        if joint is None:
            raise ValueError(f"'{tip}' is not below '{base}'")
        out.append(joint)
        node = joint.parent
    return out[::-1]


def contracted_pairs(joined: Iterable[tuple[str, str]], solid: set[str]) -> set[tuple[str, str]]:
    """Pairs (sorted names) of `solid` links joined by a joint, or by a chain of links and
    frames outside `solid` (MoveIt Setup Assistant's connection graph): `joined` holds each
    joint's (parent, child); every node outside `solid` is contracted away, its neighbours
    joined to each other."""
    near: dict[str, set[str]] = {}
    for parent, child in joined:
        near.setdefault(parent, set()).add(child)
        near.setdefault(child, set()).add(parent)
    for node in sorted(set(near) - solid):
        around = near.pop(node)
        for other in around:
            near[other].discard(node)
        for a, b in itertools.combinations(sorted(around), 2):
            near[a].add(b)
            near[b].add(a)
    return {(min(a, b), max(a, b)) for a in solid for b in near.get(a, ()) if b in solid}


def jointed_pairs(robot: Robot) -> list[tuple[str, str]]:
    """Parent-child link pairs joined directly by a joint, in joint order, then the pairs a
    loop closure joins (spec `loops`, in order): the pairs whose contacts the MJCF and USD
    exclude (MoveIt's wider `adjacent_pairs` is a derive step)."""
    links = {link.name for link in robot.links}
    pairs = [(j.parent, j.child) for j in robot.joints if j.parent in links]
    return pairs + [(lp.link1, lp.link2) for lp in robot.loops if {lp.link1, lp.link2} <= links]


def excluded_pairs(robot: Robot) -> list[tuple[str, str]]:
    """The link pairs the kit excludes from contact besides `jointed_pairs`: the derived
    `collision_pairs.always` pairs (in contact in every configuration), then `declared`
    ones (the spec's `contact_excludes`, which the source excludes), then `loop` ones (in
    contact at home around a loop closure, collision_pairs.loop_pairs); each sorted. The MJCF
    `<exclude>`s, the USD filtered pairs and the GPU scene take them."""
    block = robot.products.collision_pairs or {}
    return [(a, b) for key in ("always", "declared", "loop") for a, b in block.get(key, [])]
