"""Two mesh surfaces compared without trusting their triangulations (issue 34).

A rebuilt link solid may keep its triangle count while every triangle means something else,
so nothing here pairs vertices by index unless a fit through them is then verified on the
surfaces. `gap` is the symmetric Hausdorff distance between two surfaces, sampled: each
mesh's vertices plus seeded, area-weighted points on its triangles, each point's exact
distance to the other surface (trimesh's closest point on candidate triangles), and the
bounding box of the points off the other surface (where the shape changed). `similarity`
is the least-squares x -> s R x + t through paired points (Umeyama 1991, "Least-squares
estimation of transformation parameters between two point patterns"); `principal_axes`
and `surface_centroid` are exact per-triangle integrals, for candidate fits of meshes that
share no triangulation. Link frame, metres.
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

#: seeded sampling: the same two meshes always give the same distances (DESIGN.md)
SEED = 34
#: random surface points per mesh, beside its vertices (at most MAX_VERTICES of them)
SAMPLES = 4000
MAX_VERTICES = 4000


class Mesh:
    """Vertices (n, 3) m and triangles (m, 3) of one surface, with its proximity query built
    once (trimesh, lazily) however many points are measured against it."""

    def __init__(self, vertices: np.ndarray, faces: np.ndarray) -> None:
        self.vertices, self.faces = vertices, faces

    @functools.cached_property
    def query(self):
        """The surface for trimesh's candidate search: triangles of zero area left out (their
        points lie on their neighbours' edges)."""
        import trimesh

        tri = self.vertices[self.faces]
        area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        faces = self.faces[area > 0] if np.any(area > 0) else self.faces
        return trimesh.Trimesh(self.vertices, faces, process=False)

    @functools.cached_property
    def tree(self):
        from scipy.spatial import cKDTree

        return cKDTree(self.vertices)


class Similarity(NamedTuple):
    """x -> scale * rotation @ x + shift (link frame, m)."""

    scale: float
    rotation: np.ndarray
    shift: np.ndarray

    def apply(self, points: np.ndarray) -> np.ndarray:
        return self.scale * points @ self.rotation.T + self.shift


class Gap(NamedTuple):
    """The symmetric Hausdorff distance (m) between two surfaces, and the bounding box
    (low, high, m) of the sample points farther than the tolerance from the other surface
    (None where there are none)."""

    distance: float
    region: tuple[np.ndarray, np.ndarray] | None


def samples(mesh: Mesh, seed: int = SEED) -> np.ndarray:
    """The mesh's vertices (a seeded subset past MAX_VERTICES) and SAMPLES seeded points
    spread over its triangles by area."""
    rng = np.random.default_rng(seed)
    v = mesh.vertices
    if len(v) > MAX_VERTICES:
        v = v[np.sort(rng.choice(len(v), MAX_VERTICES, replace=False))]
    tri = mesh.vertices[mesh.faces]
    areas = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    if not len(tri) or areas.sum() <= 0:
        return v
    pick = rng.choice(len(tri), SAMPLES, p=areas / areas.sum())
    u, w = rng.random((2, SAMPLES))
    flip = u + w > 1  # fold the far half of the unit square back into the triangle
    u, w = np.where(flip, 1 - u, u), np.where(flip, 1 - w, w)
    t = tri[pick]
    points = t[:, 0] + u[:, None] * (t[:, 1] - t[:, 0]) + w[:, None] * (t[:, 2] - t[:, 0])
    return np.vstack([v, points])


def distances(points: np.ndarray, mesh: Mesh) -> np.ndarray:
    """Each point's exact distance (m) to the surface of `mesh`. trimesh (lazily) lists the
    candidate triangles (those whose box meets the ball through the nearest vertex);
    `_to_triangles` measures them, since trimesh's own closest point compares products of
    lengths with 1e-12 and misplaces points on millimetre triangles by up to 2e-5 m."""
    import trimesh

    out = np.zeros(len(points))
    if not len(points):
        return out
    found = trimesh.proximity.nearby_faces(mesh.query, points)
    counts = np.array([len(c) for c in found])
    start = 0
    for stop in _chunks(counts):
        which = np.repeat(np.arange(start, stop), counts[start:stop])
        faces = np.concatenate(found[start:stop]).astype(np.int64)
        tri = mesh.query.triangles[faces]
        d = _to_triangles(points[which], tri[:, 0], tri[:, 1], tri[:, 2])
        out[start:stop] = np.minimum.reduceat(d, np.cumsum(counts[start:stop]) - counts[start:stop])
        start = stop
    return out


def _chunks(counts: np.ndarray, pairs: int = 500_000) -> list[int]:
    """Ends of runs of points whose candidate pairs stay near `pairs` (bounded memory)."""
    ends, total = [], 0
    for i, n in enumerate(counts.tolist()):
        total += n
        if total >= pairs:
            ends.append(i + 1)
            total = 0
    if not ends or ends[-1] != len(counts):
        ends.append(len(counts))
    return ends


def _to_triangles(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Distance from each point p to the triangle (a, b, c) on its row: the closest point by
    its Voronoi region, with exact sign tests (Ericson, "Real-Time Collision Detection",
    5.1.5). Degenerate triangles are left out of `Mesh.query`."""

    def dot(x, y):
        return np.einsum("ij,ij->i", x, y)

    ab, ac, ap, bp, cp = b - a, c - a, p - a, p - b, p - c
    d1, d2, d3 = dot(ab, ap), dot(ac, ap), dot(ab, bp)
    d4, d5, d6 = dot(ac, bp), dot(ab, cp), dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        edge_ab = a + (d1 / (d1 - d3))[:, None] * ab
        edge_ac = a + (d2 / (d2 - d6))[:, None] * ac
        edge_bc = b + ((d4 - d3) / ((d4 - d3) + (d5 - d6)))[:, None] * (c - b)
        total = va + vb + vc
        inside = a + (vb / total)[:, None] * ab + (vc / total)[:, None] * ac
    regions = [
        (d1 <= 0) & (d2 <= 0),
        (d3 >= 0) & (d4 <= d3),
        (vc <= 0) & (d1 >= 0) & (d3 <= 0),
        (d6 >= 0) & (d5 <= d6),
        (vb <= 0) & (d2 >= 0) & (d6 <= 0),
        (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0),
    ]
    closest = [a, b, edge_ab, c, edge_ac, edge_bc]
    near = inside
    for region, point in zip(reversed(regions), reversed(closest), strict=True):
        near = np.where(region[:, None], point, near)
    return np.linalg.norm(p - near, axis=1)


def gap(a: Mesh, b: Mesh, tol: float) -> Gap:
    """How far apart the surfaces of `a` and `b` are, and where, sampled both ways."""
    pa, pb = samples(a), samples(b)
    da, db = distances(pa, b), distances(pb, a)
    off = np.vstack([pa[da > tol], pb[db > tol]])
    region = (off.min(axis=0), off.max(axis=0)) if len(off) else None
    return Gap(float(max(da.max(initial=0.0), db.max(initial=0.0))), region)


def same_vertices(a: Mesh, b: Mesh, tol: float) -> bool:
    """Is every vertex of each mesh within `tol` of a vertex of the other? Then the two differ
    at most in how the same points are joined into triangles (a quad split along its other
    diagonal moves a curved surface by micrometres): a new triangulation, not a new shape."""
    return all(
        len(p.vertices) and float(q.tree.query(p.vertices)[0].max()) <= tol
        for p, q in ((a, b), (b, a))
    )


def within(a: Mesh, b: Mesh, tol: float) -> bool:
    """Are `a` and `b` the same surface within `tol`: the same vertices (`same_vertices`), or
    every sample of each within `tol` of the other's surface? The vertices of `a` are
    measured first, a cheap refusal of a wrong fit."""
    if same_vertices(a, b, tol):
        return True
    if float(distances(a.vertices[:: max(1, len(a.vertices) // 64)], b).max()) > tol:
        return False
    return gap(a, b, tol).distance <= tol


def similarity(a: np.ndarray, b: np.ndarray, scaled: bool) -> Similarity:
    """The least-squares similarity (rigid when not `scaled`) carrying points a onto b."""
    ca, cb = a.mean(axis=0), b.mean(axis=0)
    u, s, vt = np.linalg.svd((b - cb).T @ (a - ca))
    d = np.ones(3)
    d[2] = np.sign(np.linalg.det(u @ vt)) or 1.0
    rot = u @ np.diag(d) @ vt
    spread = float(((a - ca) ** 2).sum())
    scale = float((s * d).sum() / spread) if scaled and spread > 0 else 1.0
    return Similarity(scale, rot, cb - scale * rot @ ca)


def _moments(mesh: Mesh) -> tuple[float, np.ndarray, np.ndarray]:
    """(area m^2, first moment m^3, second moment m^4) of the surface, exact per triangle."""
    tri = mesh.vertices[mesh.faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) / 2
    total = tri.sum(axis=1)
    first = (area[:, None] * total / 3).sum(axis=0)
    # the integral of x x^T over a triangle: A/12 (sum_i v_i v_i^T + s s^T), s = sum_i v_i
    second = np.einsum("t,tij->ij", area / 12, np.einsum("tki,tkj->tij", tri, tri))
    second += np.einsum("t,ti,tj->ij", area / 12, total, total)
    return float(area.sum()), first, second


def surface_centroid(mesh: Mesh) -> tuple[float, np.ndarray]:
    """(area m^2, area centroid m) of the surface."""
    area, first, _ = _moments(mesh)
    return area, (first / area if area > 0 else mesh.vertices.mean(axis=0))


def principal_axes(mesh: Mesh) -> np.ndarray:
    """The columns are the principal axes of the surface's second moment about its area
    centroid, largest moment first (sign and order of equal moments are arbitrary)."""
    area, first, second = _moments(mesh)
    if area <= 0:
        return np.eye(3)
    centroid = first / area
    central = second - area * np.outer(centroid, centroid)
    _values, vectors = np.linalg.eigh(central)
    return vectors[:, ::-1]
