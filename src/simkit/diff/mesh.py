"""`simkit diff` for meshes: each STL compared as a placed piece in its link frame.

A kit's meshes sit at the identity in their link frame (the URDF's <origin> is zero), so the
vertices are link-frame positions. A piece is reported when it moved (volume centroid), turned
(rigid fit of the vertices, when both files have the same triangles), changed shape (what the
rigid fit leaves, the volume, the bounding box), each against diff_tol's length rule. A new
triangulation of the same solid is not a change. GLB and USD files carry the same meshes as
the STLs (the checks compare them), so their mesh arrays are compared through the STLs.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from simkit.diff.tolerance import LENGTH_M, REL
from simkit.errors import SimkitError
from simkit.kitio.obj import read_mesh


class Piece(NamedTuple):
    """A mesh's placement and size in its link frame (m, m^2, m^3)."""

    vertices: np.ndarray
    faces: np.ndarray
    volume: float
    area: float
    centroid: np.ndarray
    low: np.ndarray
    high: np.ndarray


def piece(path: str, data: bytes) -> Piece:
    """Read a kit mesh (binary STL, or OBJ for collision pieces) as a `Piece`, or one line
    naming the file."""
    try:
        mesh = read_mesh(path, data)
    except (ValueError, IndexError) as exc:
        kind = "an OBJ" if path.lower().endswith(".obj") else "a binary STL"
        raise SimkitError(f"{path}: not {kind} ({exc})") from None
    v = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces)
    if not len(faces) or not np.all(np.isfinite(v)):
        zero = np.zeros(3)
        return Piece(v, faces, 0.0, 0.0, zero, zero, zero)
    tri = v[faces]
    cross = np.cross(tri[:, 1], tri[:, 2])
    six_vol = np.einsum("ij,ij->i", tri[:, 0], cross)
    volume = float(six_vol.sum() / 6)
    areas = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) / 2
    area = float(areas.sum())
    if abs(volume) > LENGTH_M * area:  # a closed solid: the volume centroid
        centroid = (six_vol[:, None] * tri.sum(axis=1)).sum(axis=0) / (24 * volume)
    elif area > 0:  # an open or flat surface: the area centroid
        centroid = (areas[:, None] * tri.mean(axis=1)).sum(axis=0) / area
    else:
        centroid = v.mean(axis=0)
    return Piece(v, faces, volume, area, centroid, v.min(axis=0), v.max(axis=0))


def rigid_fit(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """(rotation angle rad, largest vertex distance left) of the best rigid motion a -> b."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    u, _s, vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
    rot = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    left = float(np.linalg.norm((a - ca) @ rot.T + cb - b, axis=1).max())
    angle = float(np.arccos(np.clip((np.trace(rot) - 1) / 2, -1.0, 1.0)))
    return angle, left


def mesh_changes(path: str, old: bytes, new: bytes) -> list[tuple]:
    """(field, old, new, unit) for every change of one mesh beyond the length rule."""
    a, b = piece(path, old), piece(path, new)
    finite = [bool(np.all(np.isfinite(p.vertices))) for p in (a, b)]
    if not all(finite):  # a hostile or damaged file: say so, compare nothing
        state = ["finite" if f else "non-finite" for f in finite]
        return [("vertices", *state, "")] if finite[0] or old != new else []
    out: list[tuple] = []
    # the same triangles in the same order (an edited or moved piece): compare corner by corner
    corners = len(a.faces) == len(b.faces) and len(a.faces) > 0
    if corners:
        ca, cb = a.vertices[a.faces].reshape(-1, 3), b.vertices[b.faces].reshape(-1, 3)
        if float(np.abs(ca - cb).max()) <= LENGTH_M:
            return []
    moved = float(np.linalg.norm(b.centroid - a.centroid))
    if moved > LENGTH_M:
        out.append(("displacement", a.centroid.tolist(), b.centroid.tolist(), "m"))
    if corners:
        angle, left = rigid_fit(ca, cb)
        radius = float(np.linalg.norm(ca - ca.mean(axis=0), axis=1).max())
        if angle * radius > LENGTH_M:
            out.append(("rotation", 0.0, angle, "rad"))
        if left > LENGTH_M:
            out.append(("shape", 0.0, left, "m"))
    if abs(b.volume - a.volume) > LENGTH_M * max(a.area, b.area) + REL * abs(a.volume):
        out.append(("volume", a.volume, b.volume, "m^3"))
    size_a, size_b = (a.high - a.low).tolist(), (b.high - b.low).tolist()
    if np.abs(np.subtract(size_b, size_a)).max() > LENGTH_M:
        out.append(("bbox", size_a, size_b, "m"))
    if out and len(a.faces) != len(b.faces):
        out.append(("triangles", len(a.faces), len(b.faces), ""))
    return out
