"""A collision piece's triangles come in one fixed order (derive/collision.py `convex_mesh`).

manifold3d lists a hull's triangles in an order that varies from one call to the next (its
hull runs on threads), so a cold build on another machine could write the same piece's OBJ
with other bytes. Both of convex_mesh's paths, the manifold's own mesh and qhull's
re-triangulation of a folded one, must return the canonical order."""

from __future__ import annotations

import numpy as np

from simkit.derive.collision import convex_mesh
from simkit.model.robot import canonical_triangles


def _hull(points: np.ndarray):
    import manifold3d as mf

    return mf.Manifold.hull_points(np.asarray(points, dtype=np.float64))


def test_a_hull_piece_lists_its_triangles_in_the_canonical_order():
    points = np.random.default_rng(3).normal(size=(400, 3))
    points = points / np.linalg.norm(points, axis=1, keepdims=True) * [0.05, 0.03, 0.2]
    mesh = convex_mesh(_hull(points))  # every point on the hull: hundreds of triangles
    assert len(mesh.faces) > 500
    assert np.array_equal(mesh.faces, canonical_triangles(mesh.faces))


def test_the_same_points_in_another_order_give_the_same_triangles():
    rng = np.random.default_rng(4)
    points = rng.normal(size=(300, 3)) * 0.1
    first, second = convex_mesh(_hull(points)), convex_mesh(_hull(points[rng.permutation(300)]))
    key = np.lexsort(first.vertices.T[::-1])
    other = np.lexsort(second.vertices.T[::-1])
    assert np.array_equal(first.vertices[key], second.vertices[other])
    rename = np.empty(len(key), dtype=np.int64)
    rename[key] = np.arange(len(key))
    rename_other = np.empty(len(other), dtype=np.int64)
    rename_other[other] = np.arange(len(other))
    same_first = canonical_triangles(rename[first.faces])
    same_second = canonical_triangles(rename_other[second.faces])
    assert np.array_equal(same_first, same_second)
