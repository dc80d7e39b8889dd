"""Shading normals of a triangle mesh: smooth across curved surfaces, sharp at creases.

Each face corner gets the angle-weighted mean of the normals of the faces around its vertex
that lie within `CREASE_DEG` of its own face (Thuermer and Wuethrich, "Computing vertex normals
from polygonal meshes", 1998, weighted by the corner angle). A cylinder's 48 facets (7.5
degrees apart, derive/solids.py) shade as one round surface, while its rim (90 degrees) and a
box's edges stay sharp, and a planar face keeps its own normal exactly.

Vertices are matched by position (exact), so a mesh whose faces do not share vertices still
shades smoothly. The GLB (per-vertex normals) and the USD (faceVarying normals) use the same
corner normals, so both shade alike. Normals are unit vectors in the mesh's frame, rounded
to 7 decimals (shading needs no more) so the files they go into are stable.
"""

from __future__ import annotations

import hashlib
import math

import numpy as np

#: degrees: faces meeting at a larger angle than this are shaded with a crease between them
CREASE_DEG = 35.0
DECIMALS = 7


def face_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) unit normals by the right-hand rule of each face's winding; 0 for a degenerate
    face."""
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return n / np.where(length > 0, length, 1.0)


def _corner_angles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) interior angle (rad) of each face at each of its corners."""
    tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces)]
    angles = np.empty(tri.shape[:2])
    for k in range(3):
        a = tri[:, (k + 1) % 3] - tri[:, k]
        b = tri[:, (k + 2) % 3] - tri[:, k]
        denom = np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1)
        cos = np.einsum("ij,ij->i", a, b) / np.where(denom > 0, denom, 1.0)
        angles[:, k] = np.where(denom > 0, np.arccos(np.clip(cos, -1.0, 1.0)), 0.0)
    return angles


#: corner pairs handled at once: bounds memory on a vertex shared by thousands of faces
PAIRS_PER_CHUNK = 1 << 21


def _pairs(vertex_of_corner: np.ndarray, limit: int | None = None):
    """Every ordered pair (a, b) of corners at the same vertex, a == b included, in chunks of
    about `limit` pairs (one vertex's corners in row blocks where it alone has more). The
    pairs come in the same order however they are chunked."""
    limit = limit or PAIRS_PER_CHUNK
    order = np.argsort(vertex_of_corner, kind="stable")
    ids = vertex_of_corner[order]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    sizes = np.diff(np.r_[starts, len(ids)])
    first = 0
    while first < len(starts):
        cost = np.cumsum(sizes[first:] ** 2)
        last = first + max(1, int(np.searchsorted(cost, limit, side="right")))
        if last - first == 1 and sizes[first] ** 2 > limit:  # one vertex, many faces
            group = order[starts[first] : starts[first] + sizes[first]]
            rows = max(1, limit // int(sizes[first]))
            for r in range(0, len(group), rows):
                block = group[r : r + rows]
                yield np.repeat(block, len(group)), np.tile(group, len(block))
        else:
            yield _group_pairs(order, starts[first:last], sizes[first:last])
        first = last


def _group_pairs(order: np.ndarray, starts: np.ndarray, sizes: np.ndarray):
    """All pairs within each group of sorted positions starts[i] .. starts[i] + sizes[i]."""
    group = np.repeat(np.arange(len(starts)), sizes)  # group of each sorted position
    positions = np.arange(starts[0], starts[0] + int(sizes.sum()))  # the groups are contiguous
    reps = sizes[group]
    a = np.repeat(positions, reps)
    offset = np.arange(int(reps.sum())) - np.repeat(np.cumsum(reps) - reps, reps)
    b = np.repeat(starts[group], reps) + offset
    return order[a], order[b]


#: corner normals by the digest of their mesh and crease angle: the GLB and the USD emitters
#: shade the same link solids (a CAD mesh's normals take a second)
_DONE: dict[bytes, np.ndarray] = {}
_DONE_MAX = 256


def corner_normals(
    vertices: np.ndarray, faces: np.ndarray, crease_deg: float = CREASE_DEG
) -> np.ndarray:
    """(F, 3, 3) unit shading normal at each corner of each face (mesh frame); computed once
    per mesh content (a fresh copy each call)."""
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    digest = hashlib.sha256(vertices.tobytes())
    digest.update(faces.tobytes())
    digest.update(f"{vertices.shape} {faces.shape} {crease_deg!r}".encode())
    key = digest.digest()
    if key not in _DONE:
        if len(_DONE) >= _DONE_MAX:
            _DONE.clear()
        _DONE[key] = _corner_normals(vertices, faces, crease_deg)
    return _DONE[key].copy()


def _corner_normals(vertices: np.ndarray, faces: np.ndarray, crease_deg: float) -> np.ndarray:
    faces = np.asarray(faces, dtype=np.int64)
    _unique, welded = np.unique(np.asarray(vertices), axis=0, return_inverse=True)
    vertex = welded.reshape(-1)[faces].reshape(-1)  # welded vertex of each corner
    fn = np.repeat(face_normals(vertices, faces), 3, axis=0)  # face normal of each corner
    weighted = fn * _corner_angles(vertices, faces).reshape(-1, 1)
    cos = math.cos(math.radians(crease_deg))
    out, spare = np.zeros_like(fn), np.zeros_like(fn)
    for a, b in _pairs(vertex):
        near = np.einsum("ij,ij->i", fn[a], fn[b]) >= cos
        np.add.at(out, a[near], weighted[b[near]])
        np.add.at(spare, a, weighted[b])
    # a degenerate face has no direction of its own: it takes its vertex's mean normal
    lost = np.linalg.norm(out, axis=1) < 1e-12
    if lost.any():
        out[lost] = spare[lost]
        out[np.linalg.norm(out, axis=1) < 1e-12] = (0.0, 0.0, 1.0)
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    out = np.round(out, DECIMALS) + 0.0  # no -0
    out /= np.linalg.norm(out, axis=1, keepdims=True)
    return out.reshape(len(faces), 3, 3)


def split_vertices(
    vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(positions, normals, faces) with one vertex per distinct (vertex, corner normal), for
    formats whose normals are per vertex (glTF): a vertex on a crease is split in two or more.
    Vertices stay in the mesh's order, each one's copies by normal."""
    faces = np.asarray(faces, dtype=np.int64)
    flat = normals.reshape(-1, 3)
    key = np.column_stack([faces.reshape(-1).astype(np.float64), flat])
    unique, inverse = np.unique(key, axis=0, return_inverse=True)
    index = unique[:, 0].astype(np.int64)
    positions = np.asarray(vertices)[index]
    return positions, unique[:, 1:], inverse.reshape(-1).reshape(faces.shape)
