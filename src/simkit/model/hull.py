"""How far points lie outside a convex hull, fast for points on or near its surface.

A point's signed distance to a convex hull's boundary, seen from outside, is the largest of
its signed distances to the hull's facet planes (m, > 0 outside, <= 0 inside). Taken over
every plane that is a points x facets matrix: for a given collision hull of 13,000 facets
tested at its 20,000 vertices and face centres, 2 GB and 9 s. But to show that a point is
not deep inside (the question the convexity tests ask), one plane at or above the floor is
enough, and the planes of the facets at the point's nearest hull vertices almost always
give one. Only the other points are measured against every plane.
"""

from __future__ import annotations

import numpy as np

#: nearest hull vertices whose facets are tried first for each point
NEAREST = 3
#: at most this many of each such vertex's facets (a cone's apex has hundreds)
FACETS_PER_VERTEX = 32
#: matrix entries per block of the full measurement (8 MB of float64)
CHUNK = 1 << 20


def facet_planes(vertices: np.ndarray):
    """scipy's qhull ConvexHull of `vertices` (m); its `equations` are unit-normal facet
    planes. Raises QhullError or ValueError for a flat or too small point set."""
    from scipy.spatial import ConvexHull

    return ConvexHull(np.asarray(vertices, dtype=float))


def facet_depth(points: np.ndarray, hull, floor: float) -> np.ndarray:
    """Per point, the largest signed distance to `hull`'s facet planes (m, > 0 outside):
    exact for every point below `floor` (m); a point whose nearby facets already put it at
    or above `floor` gets that value, a lower bound of the exact one that is >= `floor`."""
    points = np.asarray(points, dtype=float)
    planes = hull.equations
    near = _nearby_planes(points, hull)
    found = np.einsum("ikj,ij->ik", planes[near, :3], points) + planes[near, 3]
    depth = found.max(axis=1)
    rest = np.flatnonzero(depth < floor)
    rows = max(1, CHUNK // len(planes))
    for start in range(0, len(rest), rows):
        block = rest[start : start + rows]
        depth[block] = (points[block] @ planes[:, :3].T + planes[:, 3]).max(axis=1)
    return depth


def _nearby_planes(points: np.ndarray, hull) -> np.ndarray:
    """For each point, the facets of its `NEAREST` nearest hull vertices (at most
    `FACETS_PER_VERTEX` each, padded by repeating one), as a points x k matrix of indices."""
    from scipy.spatial import cKDTree

    corners = hull.vertices
    k = min(NEAREST, len(corners))
    _, nearest = cKDTree(hull.points[corners]).query(points, k=k)
    nearest = corners[np.asarray(nearest).reshape(len(points), k)]
    facets = np.repeat(np.arange(len(hull.simplices)), 3)
    order = np.argsort(hull.simplices.ravel(), kind="stable")
    owners, facets = hull.simplices.ravel()[order], facets[order]
    start = np.searchsorted(owners, np.arange(len(hull.points)))
    count = np.searchsorted(owners, np.arange(len(hull.points)), side="right") - start
    width = min(int(count[corners].max()), FACETS_PER_VERTEX)
    offsets = np.minimum(np.arange(width)[None, :], count[nearest].reshape(-1, 1) - 1)
    picked = facets[start[nearest].reshape(-1, 1) + offsets]
    return picked.reshape(len(points), k * width)


#: grid cells per side for `plane_max`'s plane culling
CELLS = 16


def plane_values(points: np.ndarray, planes: np.ndarray) -> np.ndarray:
    """n . p + d for every point (rows) and plane (columns; rows n_x, n_y, n_z, d), term by
    term: each entry is the same float however the points and planes are split (a matrix
    product's rounding depends on the kernel BLAS picks for the shape)."""
    n, d = planes[:, :3], planes[:, 3]
    return points[:, :1] * n[:, 0] + points[:, 1:2] * n[:, 1] + points[:, 2:3] * n[:, 2] + d


def _blocks_max(points: np.ndarray, planes: np.ndarray) -> np.ndarray:
    """max over `planes` of `plane_values`, in blocks of at most `CHUNK` entries."""
    rows = max(1, CHUNK // max(len(planes), 1))
    starts = range(0, len(points), rows)
    return np.concatenate([plane_values(points[i : i + rows], planes).max(axis=1) for i in starts])


def plane_max(points: np.ndarray, planes: np.ndarray) -> np.ndarray:
    """Per point, the largest n . p + d over `planes` (rows n_x, n_y, n_z, d; unit normals,
    m): exact, cell by cell. The points are binned in a grid of `CELLS` per side; for a cell
    of radius r about c, a plane can give a point its maximum only if its value at c plus r
    reaches the largest value at c minus r, so each cell is measured against those planes
    only (a 13,000-facet hull against 20,000 visual vertices: a few hundred planes a cell,
    not all of them). Each value is `plane_values`', so the result does not depend on how
    the points fall into cells or blocks."""
    points = np.asarray(points, dtype=float)
    if not len(points):
        return np.zeros(0)
    if len(points) * len(planes) <= CHUNK:
        return _blocks_max(points, planes)
    low = points.min(axis=0)
    size = max(float((points.max(axis=0) - low).max()) / CELLS, 1e-9)
    keys = np.floor((points - low) / size).astype(np.int64)
    cells, owner = np.unique(keys, axis=0, return_inverse=True)
    order = np.argsort(owner.ravel(), kind="stable")
    bounds = np.searchsorted(owner.ravel()[order], np.arange(len(cells) + 1))
    out = np.empty(len(points))
    radius = size * np.sqrt(3.0) / 2.0
    for k, key in enumerate(cells):
        members = order[bounds[k] : bounds[k + 1]]
        at_centre = planes[:, :3] @ (low + (key + 0.5) * size) + planes[:, 3]
        keep = at_centre + radius >= at_centre.max() - radius - 1e-12
        out[members] = _blocks_max(points[members], planes[keep])
    return out
