"""Convex hulls of point sets (m) that hold every point: the collision pieces' hulls.

manifold3d's `hull_points` (its QuickHull) can leave an input point outside the hull it
returns where many points lie on or near one plane: a thin CoACD piece grown by `cover` to
take in the visual samples of a flat face (a quadruped's body plate, 0.39 m by 0.03 m) lost
one visual vertex 0.084 mm outside, and the kit failed `collision.cover` (tolerance 0.01 mm).
The same inputs make its inverted faces (elalish/manifold#1785), which `convex_mesh` mends
from the hull's vertices, but a vertex it dropped is no longer there to mend from. So every
hull is checked against its points, and where one lies outside, qhull's triangulated hull of
the points is used instead. A hull that holds its points is kept as manifold3d made it (the
same pieces, the same bytes).
"""

from __future__ import annotations

import numpy as np

from simkit.model.hull import facet_planes, plane_max
from simkit.model.robot import Mesh

INSIDE_TOL = 1e-7  # m: a point this close to a hull's face counts as inside


def qhull_mesh(points: np.ndarray, hull=None) -> Mesh:
    """qhull's triangulated convex hull of `points` (m; `hull`: their `facet_planes` where
    already made): its vertices in input order, each triangle wound outward. Raises
    QhullError or ValueError for a flat or too small set."""
    points = np.asarray(points, dtype=np.float64)
    hull = facet_planes(points) if hull is None else hull
    keep = np.sort(hull.vertices)
    index = np.full(len(points), -1, dtype=np.int64)
    index[keep] = np.arange(len(keep))
    faces = index[hull.simplices]
    vertices = points[keep]
    tri = vertices[faces]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flip = np.einsum("ij,ij->i", normal, hull.equations[:, :3]) < 0
    faces[flip] = faces[flip][:, ::-1]
    return Mesh.of(vertices, faces)


def farthest_outside(points: np.ndarray, vertices: np.ndarray) -> float:
    """How far (m) the farthest of `points` lies outside the convex hull of `vertices`
    (<= 0: all inside); inf where `vertices` span no solid."""
    from scipy.spatial import QhullError

    try:
        planes = facet_planes(vertices).equations
    except (QhullError, ValueError):
        return float("inf")
    return float(plane_max(np.asarray(points, dtype=np.float64), planes).max())


def hull_points(points: np.ndarray):
    """The convex hull of `points` (m) as a manifold3d Manifold that holds every point to
    INSIDE_TOL: manifold3d's own, else qhull's (module doc); manifold3d's own, with no
    volume, for a flat set (the callers drop it)."""
    import manifold3d as mf
    from scipy.spatial import QhullError

    points = np.ascontiguousarray(points, dtype=np.float64)
    hull = mf.Manifold.hull_points(points)
    if hull.is_empty() or hull.volume() <= 0:
        return hull
    made = np.asarray(hull.to_mesh64().vert_properties, dtype=np.float64)[:, :3]
    if farthest_outside(points, made) <= INSIDE_TOL:
        return hull
    try:
        mesh = qhull_mesh(points)
    except (QhullError, ValueError):
        return hull
    return mf.Manifold(
        mf.Mesh64(
            vert_properties=np.array(mesh.vertices, np.float64),
            tri_verts=np.array(mesh.faces, np.uint64),
        )
    )
