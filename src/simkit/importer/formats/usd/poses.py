"""Poses of a USD stage as 4x4 numpy transforms (column vectors, metres), and the stage
units: `metersPerUnit` scales every length, `kilogramsPerUnit` every mass, and a Y-up stage
is turned Z-up (a +90 degree turn about x) where the robot meets the world."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from simkit.importer.read.model import At, Pose


@dataclass(frozen=True)
class Units:
    """The stage's metres and kilograms per unit, and its turn to Z up (3x3)."""

    meters: float = 1.0
    kilograms: float = 1.0
    up: np.ndarray = field(default_factory=lambda: np.eye(3))

    @staticmethod
    def of(stage) -> Units:
        from pxr import UsdGeom, UsdPhysics

        meters = float(UsdGeom.GetStageMetersPerUnit(stage)) or 1.0
        kilograms = float(UsdPhysics.GetStageKilogramsPerUnit(stage)) or 1.0
        y_up = UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
        up = np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]) if y_up else np.eye(3)
        return Units(meters, kilograms, up)


def quat_matrix(quat) -> np.ndarray:
    """The rotation of a quaternion (w, x, y, z), normalised."""
    w, x, y, z = (float(v) for v in quat)
    n = np.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def make(rot: np.ndarray, pos) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rot, np.asarray(pos, dtype=float)
    return out


def inv(t: np.ndarray) -> np.ndarray:
    """The inverse of a rigid transform."""
    rot = t[:3, :3].T
    return make(rot, -rot @ t[:3, 3])


def split(gf_matrix, meters: float) -> tuple[np.ndarray, np.ndarray]:
    """(rigid transform with translation in metres, per-axis scale) of a Gf.Matrix4d
    (USD's row-vector convention), its scale and shear taken out."""
    m = np.array(gf_matrix, dtype=float).T
    scale = np.linalg.norm(m[:3, :3], axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    u, _, vt = np.linalg.svd(m[:3, :3] / scale)
    rot = u @ vt
    if np.linalg.det(rot) < 0:
        rot = -rot
    return make(rot, m[:3, 3] * meters), scale


def world(cache, prim, meters: float) -> tuple[np.ndarray, np.ndarray]:
    """(the prim's world pose, rigid, m; its world scale)."""
    return split(cache.GetLocalToWorldTransform(prim), meters)


def relative(cache, prim, ancestor, meters: float) -> np.ndarray:
    """The prim's full transform (scale kept, translation in metres) in `ancestor`'s frame."""
    m, _ = cache.ComputeRelativeTransform(prim, ancestor)
    out = np.array(m, dtype=float).T
    out[:3, 3] *= meters
    return out


def rpy(mat: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw (fixed x-y-z, rad) of a rotation matrix."""
    pitch = float(np.arcsin(np.clip(-mat[2, 0], -1.0, 1.0)))
    if abs(mat[2, 0]) < 1.0 - 1e-12:
        return np.array([np.arctan2(mat[2, 1], mat[2, 2]), pitch, np.arctan2(mat[1, 0], mat[0, 0])])
    return np.array([np.arctan2(-mat[1, 2], mat[1, 1]), pitch, 0.0])


def fmt(values) -> str:
    """Numbers as the shortest text that reads back exactly."""
    return " ".join(repr(float(v)) for v in np.ravel(values))


def floats(values) -> tuple[float, ...]:
    """Numbers as plain floats (the model is typed), in order."""
    return tuple(float(v) for v in np.ravel(values))


def pose(t: np.ndarray) -> Pose:
    """The model `Pose` (m, URDF rpy rad) of transform `t`; its place has no line (a
    stage has none: every node's `At.sourceline` is None)."""
    xyz, turn = floats(t[:3, 3]), floats(rpy(t[:3, :3]))
    return Pose(xyz, turn, At("origin"))  # type: ignore[arg-type]


#: USD value types stored as 32-bit floats: read back as the shortest decimal that gives
#: the same float32 (the number the file was written with), not its float64 widening
FLOAT32 = {"float", "float2", "float3", "float4", "point3f", "vector3f", "normal3f", "quatf"}


def get(prim, name: str):
    """The attribute's value (None: no such attribute or no value), float32 values as the
    decimals they were written from (FLOAT32); a quaternion as (w, x, y, z)."""
    attr = prim.GetAttribute(name)
    if not attr:
        return None
    value = attr.Get()
    if value is None:
        return None
    kind = str(attr.GetTypeName())
    if kind.startswith("quat"):
        value = (value.GetReal(), *value.GetImaginary())
    if kind not in FLOAT32:
        return value if isinstance(value, (str, bool)) else _floats(value, float)
    return _floats(value, lambda v: float(str(np.float32(v))))


def _floats(value, conv):
    if hasattr(value, "__len__"):
        return tuple(conv(v) for v in value)
    return conv(value)
