"""Per-link collision geometry: up to ten convex pieces in the link frame (m), and their quality.

Methods (spec `links[].collision`, issue 3 "What to build" 1):
- `convex` (chosen by `auto` for a plain union of convex primitives): the primitives' own
  convex meshes, exact; above `MAX_PIECES` the pair whose merged hull adds the least volume is
  merged, greedily.
- `coacd` (chosen by `auto` for mesh-sourced solids and solids with subtractions): CoACD, tuned
  as issue 3 measured (threshold 0.1, 60 MCTS iterations, 10 nodes, preprocessing set
  explicitly) on a coarse manifold copy of the solid, never on the visual mesh; then every
  visual vertex and face centre left outside the hulls is added to the nearest hull.
- `primitives`: the spec's collision primitives, emitted as primitives by URDF/MJCF/USD.
- `mesh`: the visual solid's convex hull, one piece (issue 25: written as an OBJ piece like
  any other, never as a collision pointing at the visual STL, which Drake's SceneGraph refuses).
- `given`: the spec's `collision_shapes` (an imported URDF's own collision geometry), one
  convex hull each, merged down to `MAX_PIECES`, then grown to cover the visual like `coacd`.

The kit page ("What a kit contains", "Geometry"): collision meshes are convex pieces, up to ten
per link, link frame, metres.
"""

from __future__ import annotations

from dataclasses import asdict

import numpy as np

from simkit.derive.hulls import INSIDE_TOL, hull_points, qhull_mesh
from simkit.errors import SpecError
from simkit.model.hull import facet_depth, facet_planes, plane_max
from simkit.model.hull import plane_values as hull_plane_values
from simkit.model.robot import Link, Mesh, Shape, canonical_triangles

MAX_PIECES = 10  # kit page: "convex pieces per link, up to ten"
#: CoACD settings from issue 3's measurements ("Tuned CoACD": 3.8 s a link, 10 pieces).
#: The input is already a closed manifold, so CoACD's own remeshing is switched off.
COACD_PARAMS: dict[str, object] = {
    "threshold": 0.1,
    "max_convex_hull": MAX_PIECES,
    "preprocess_mode": "off",
    "preprocess_resolution": 50,
    "resolution": 2000,
    "mcts_nodes": 10,
    "mcts_iterations": 60,
    "mcts_max_depth": 3,
    "pca": False,
    "merge": True,
    "decimate": False,
    "max_ch_vertex": 256,
    "extrude": False,
    "extrude_margin": 0.01,
    "apx_mode": "ch",
}
COARSE_TOLERANCE = 0.0005  # m: manifold `simplify` tolerance for the coarse CoACD input
COARSE_MAX_TRIANGLES = 5000  # issue 3: CoACD input of 2.5k to 5k triangles
#: Runs of CoACD in this process, plus those reported back by pool workers (tests count them).
COACD_RUNS = 0


def method_of(link: Link) -> str:
    """The concrete method for a link: `auto` becomes `convex` or `coacd`."""
    from simkit.derive.solids import is_convex_union

    if link.collision_method == "auto":
        return "convex" if is_convex_union(link.shapes) else "coacd"
    if link.collision_method == "convex" and not is_convex_union(link.shapes):
        raise SpecError(
            link.name,
            None,
            "collision",
            f"link '{link.name}': 'convex' needs a union of convex primitives "
            "(no mesh, no subtract); use 'auto' or 'coacd'",
        )
    return link.collision_method


#: Per-method result revisions, in the cache key only where a method's result changed, so
#: the other methods' cached pieces (CoACD's, minutes a robot) stay valid. `mesh` 2: the hull
#: became a piece (issue 25); before, no pieces. `coacd` and `given` 2: a hull holds every
#: point it is made of (derive/hulls.py); before, a grown piece could drop a visual vertex.
METHOD_REVISION = {"mesh": 2, "coacd": 2, "given": 2}


def key_params(link: Link, seed: int) -> dict[str, object]:
    """Every parameter the result depends on (for the cache key)."""
    method = method_of(link)
    revision = {"revision": METHOD_REVISION[method]} if method in METHOD_REVISION else {}
    return {
        "method": method,
        **revision,
        "shapes": [asdict(s) for s in link.shapes],
        "collision_primitives": [asdict(s) for s in link.collision_primitives],
        "max_pieces": MAX_PIECES,
        "coacd": COACD_PARAMS,
        "coarse_tolerance": COARSE_TOLERANCE,
        "coarse_max_triangles": COARSE_MAX_TRIANGLES,
        "seed": seed,
    }


# --- manifold helpers -------------------------------------------------------------------


def _manifold(mesh: Mesh):
    import manifold3d as mf

    return mf.Manifold(
        mf.Mesh64(
            vert_properties=np.array(mesh.vertices, np.float64),
            tri_verts=np.array(mesh.faces, np.uint64),
        )
    )


def _hull(points: np.ndarray):
    """The points' convex hull, holding every one of them (derive/hulls.py)."""
    return hull_points(points)


def _union(parts: list):
    import manifold3d as mf

    return mf.Manifold.batch_boolean(parts, mf.OpType.Add) if len(parts) > 1 else parts[0]


def _mesh(solid) -> Mesh:
    from simkit.derive.solids import to_mesh

    return to_mesh(solid)


#: m: how far a face of a hull may lie inside the exact convex hull of its vertices
CONVEX_EPS = 1e-7


def convex_mesh(solid) -> Mesh:
    """The mesh of a hull, exactly convex. manifold3d's hull of near-coplanar points (a piece
    grown by `cover` to take in visual vertices just outside it) can fold faces inward by a
    fraction of a millimetre (a 7-dof arm's upper link in the corpus: 0.4 mm); such a mesh is
    replaced by qhull's triangulated hull of the same vertices, faces turned outward. Either
    way the triangles come in one fixed order (`canonical_triangles`): manifold3d lists a
    hull's triangles in an order that varies between calls, and a cold build elsewhere wrote
    the same piece's OBJ with other bytes."""
    mesh = _mesh(solid)
    hull = facet_planes(mesh.vertices)
    samples = np.vstack([mesh.vertices, mesh.vertices[mesh.faces].mean(axis=1)])
    if -facet_depth(samples, hull, -CONVEX_EPS).min() <= CONVEX_EPS:
        return Mesh.of(mesh.vertices, canonical_triangles(mesh.faces))
    outer = qhull_mesh(mesh.vertices, hull)
    return Mesh.of(outer.vertices, canonical_triangles(outer.faces))


# --- exact convex pieces -----------------------------------------------------------------


def merge_greedy(hulls: list, limit: int = MAX_PIECES) -> list:
    """Merge convex manifolds pairwise until at most `limit` remain; each step merges the pair
    whose hull adds the least volume over the pair's union (issue 3, "Exact convex pieces")."""
    import manifold3d as mf

    hulls = list(hulls)

    def cost(a, b) -> float:
        return mf.Manifold.batch_hull([a, b]).volume() - (a + b).volume()

    costs = {
        (i, j): cost(hulls[i], hulls[j])
        for i in range(len(hulls))
        for j in range(i + 1, len(hulls))
    }
    alive = list(range(len(hulls)))
    while len(alive) > limit:
        i, j = min(
            ((a, b) for a, b in costs if a in alive and b in alive),
            key=lambda pair: (costs[pair], pair),
        )
        hulls.append(mf.Manifold.batch_hull([hulls[i], hulls[j]]))
        new = len(hulls) - 1
        alive = [k for k in alive if k not in (i, j)]
        for k in alive:
            costs[(k, new)] = cost(hulls[k], hulls[new])
        alive.append(new)
    return [hulls[k] for k in alive]


def convex_pieces(shapes: tuple[Shape, ...], limit: int = MAX_PIECES) -> list:
    """Each additive primitive's own convex manifold, merged down to `limit` pieces."""
    from simkit.derive.solids import primitive_solid

    hulls = [primitive_solid(s).hull() for s in shapes if not s.subtract]
    return merge_greedy(hulls, limit) if len(hulls) > limit else hulls


# --- CoACD ------------------------------------------------------------------------------


def coarse_solid(solid: Mesh):
    """A coarse manifold copy of the solid for CoACD: `simplify` within COARSE_TOLERANCE,
    loosened until it has at most COARSE_MAX_TRIANGLES triangles."""
    coarse = _manifold(solid)
    tol = COARSE_TOLERANCE
    simplified = coarse.simplify(tol)
    while simplified.num_tri() > COARSE_MAX_TRIANGLES:
        tol *= 2
        simplified = coarse.simplify(tol)
    return simplified


def run_coacd(solid: Mesh, seed: int) -> list:
    """CoACD on the coarse solid; convex manifolds (hulls of CoACD's parts)."""
    global COACD_RUNS
    import coacd  # lazy: loads OpenMP; pool workers set OMP_NUM_THREADS=1 first

    coarse = _mesh(coarse_solid(solid))
    coacd.set_log_level("error")
    parts = coacd.run_coacd(
        coacd.Mesh(np.asarray(coarse.vertices, np.float64), np.asarray(coarse.faces, np.int64)),
        seed=seed,
        **COACD_PARAMS,
    )
    COACD_RUNS += 1
    hulls = [_hull(np.asarray(v)) for v, _f in parts if len(v) >= 4]
    hulls = [h for h in hulls if not h.is_empty() and h.volume() > 0]
    return merge_greedy(hulls) if len(hulls) > MAX_PIECES else hulls


def _halfspaces(hull: Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Outward unit normals and offsets (n . x <= d inside) of a convex mesh's faces."""
    tri = hull.vertices[hull.faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1)
    keep = length > 1e-15
    n = n[keep] / length[keep, None]
    return n, np.einsum("ij,ij->i", n, tri[keep, 0])


def outside_depth(points: np.ndarray, hull: Mesh) -> np.ndarray:
    """How far each point lies outside a convex mesh (max face-plane distance; <= 0 inside).

    Exact, cell by cell (model/hull.py `plane_max`): a detailed hull (a hobby arm's base,
    9,000 faces, against 100,000 surface samples) drops from every plane for every point (66 s
    on 2 cores) to the few planes facing each cell."""
    n, d = _halfspaces(hull)
    return plane_max(np.asarray(points, dtype=float), np.column_stack([n, -d]))


def plane_values(points: np.ndarray, n: np.ndarray, d: np.ndarray) -> np.ndarray:
    """n . p - d for every point (rows) and plane (columns), term by term (model/hull.py)."""
    return hull_plane_values(points, np.column_stack([n, -d]))


def cover(hulls: list, samples: np.ndarray) -> list:
    """Grow hulls so every sample point lies inside one: each uncovered point joins the hull it
    lies least far outside. Growing a hull keeps covered points covered."""
    meshes = [_mesh(h) for h in hulls]
    depth = np.stack([outside_depth(samples, m) for m in meshes])
    uncovered = depth.min(axis=0) > INSIDE_TOL
    if not uncovered.any():
        return hulls
    owner = depth[:, uncovered].argmin(axis=0)
    out = []
    for i, mesh in enumerate(meshes):
        extra = samples[uncovered][owner == i]
        out.append(_hull(np.vstack([mesh.vertices, extra])) if len(extra) else hulls[i])
    return out


# --- quality ----------------------------------------------------------------------------


def surface_samples(mesh: Mesh) -> np.ndarray:
    """Vertices and face centres of a mesh (deterministic surface samples, m)."""
    return np.vstack([mesh.vertices, mesh.vertices[mesh.faces].mean(axis=1)])


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    t = np.clip(
        np.einsum("ij,ij->i", p - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-30),
        0.0,
        1.0,
    )
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)


def _point_triangle_distance(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Distance from points p[k] to triangles tri[k] (pairs, vectorized)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    n = np.cross(b - a, c - a)
    nn = np.maximum(np.einsum("ij,ij->i", n, n), 1e-30)
    inside = np.ones(len(p), dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.einsum("ij,ij->i", np.cross(v - u, p - u), n) >= 0
    plane = np.abs(np.einsum("ij,ij->i", p - a, n)) / np.sqrt(nn)
    edges = np.minimum(
        np.minimum(_segment_distance(p, a, b), _segment_distance(p, b, c)),
        _segment_distance(p, c, a),
    )
    return np.where(inside, plane, edges)


def max_distance_to_surface(points: np.ndarray, surface: Mesh, nearest: int = 4) -> float:
    """Largest distance from `points` to the triangle surface `surface` (m), exact.

    Every triangle lies in the ball about its centroid through its farthest corner, so
    |p - centroid| - radius is a lower bound. The `nearest` triangles by centroid (a KD-tree)
    give each point an upper bound; points are taken by that bound, largest first, each one
    compared exactly with every triangle whose lower bound is within its upper bound, and
    the walk stops at the first point whose upper bound cannot beat the maximum so far.
    (It replaced a points x triangles bound matrix: that hobby arm's base took 77 s, on 2
    cores.)"""
    from scipy.spatial import cKDTree

    if not len(points):
        return 0.0
    tri = surface.vertices[surface.faces]
    centre = tri.mean(axis=1)
    radius = np.linalg.norm(tri - centre[:, None, :], axis=2).max(axis=1)
    tree = cKDTree(centre)
    k = min(nearest, len(tri))
    _dist, first = tree.query(points, k=k)
    first = np.asarray(first).reshape(len(points), k)
    rows = np.repeat(np.arange(len(points)), k)
    upper = _point_triangle_distance(points[rows], tri[first.ravel()]).reshape(-1, k).min(axis=1)
    worst, slack, reach = 0.0, 1e-9, float(radius.max())
    order = np.argsort(-upper, kind="stable")
    start, batch = 0, 16
    while start < len(order) and upper[order[start]] > worst:
        # a batch of points, largest upper bound first: a point whose bound cannot beat the
        # maximum cannot raise it, so measuring a few past the stop changes nothing
        ids = order[start : start + batch]
        ids = ids[upper[ids] > worst]
        start, batch = start + batch, min(batch * 2, 1024)
        found = tree.query_ball_point(points[ids], upper[ids] + reach + slack)
        rows = np.repeat(np.arange(len(ids)), [len(f) for f in found])
        near = np.concatenate([np.asarray(f, dtype=int) for f in found] + [np.zeros(0, int)])
        bound = upper[ids][rows] + slack
        keep = np.linalg.norm(centre[near] - points[ids][rows], axis=1) - radius[near] <= bound
        rows, near = rows[keep], near[keep]
        best = upper[ids].copy()
        if len(near):
            exact = _point_triangle_distance(points[ids][rows], tri[near])
            np.minimum.at(best, rows, exact)
        worst = max(worst, float(best.max()))
    return worst


def quality(solid: Mesh, pieces: list) -> dict:
    """Pieces, hull-volume ratios, coverage (volumes by manifold3d) and the largest distance
    from the visual surface (vertices and face centres) to the collision surface, the boundary
    of the pieces' union (m)."""
    union = _union(pieces)
    visual = _manifold(solid)
    volume = visual.volume()
    samples = surface_samples(solid)
    # a sample on one piece's boundary and inside no piece lies on the union's surface: 0 m
    depth = np.stack([outside_depth(samples, _mesh(p)) for p in pieces])
    on_surface = (np.abs(depth) <= INSIDE_TOL).any(axis=0) & (depth >= -INSIDE_TOL).all(axis=0)
    rest = samples[~on_surface]
    return {
        "pieces": len(pieces),
        "hull_volume_ratio": union.volume() / volume,
        "hull_volume_sum_ratio": sum(p.volume() for p in pieces) / volume,
        # booleans of nearly coincident surfaces can round slightly below zero: clamp
        "coverage": 1.0 - min(max((visual - union).volume() / volume, 0.0), 1.0),
        "visual_to_collision_max_m": max_distance_to_surface(rest, _mesh(union))
        if len(rest)
        else 0.0,
    }


# --- the per-link step ------------------------------------------------------------------


def _method_hulls(link: Link, method: str, seed: int) -> list:
    """The convex manifolds a method gives before `cover` (none for `mesh`)."""
    if method == "convex":
        return convex_pieces(link.shapes)
    if method == "given":
        hulls = [_hull(h.vertices) for h in link.given_hulls]
        hulls = [h for h in hulls if not h.is_empty() and h.volume() > 0]
        return merge_greedy(hulls) if len(hulls) > MAX_PIECES else hulls
    if method == "coacd":
        return run_coacd(link.solid, seed)
    return []


def link_collision(link: Link, seed: int) -> tuple[tuple[Mesh, ...], dict]:
    """Collision pieces (empty where the emitters use primitives, or the link has no solid)
    and the quality report of one link whose `solid` is derived. A link with a solid and no
    primitives always gets pieces: where its method gives none (`mesh`, or nothing left of
    a decomposition) the solid's convex hull is its one piece, so no emitter has to fall
    back to the visual mesh."""
    from simkit.derive.solids import primitive_solid

    method = method_of(link)
    if method == "primitives":
        shown = [primitive_solid(s).hull() for s in link.collision_primitives]
        report = (
            {"method": method, **quality(link.solid, shown)}
            if link.solid and shown
            else {"method": method, "pieces": len(link.collision_primitives)}
        )
        return (), report
    if link.solid is None:
        return (), {"method": method, "pieces": 0}
    hulls = _method_hulls(link, method, seed)
    if hulls and method in ("given", "coacd"):
        hulls = cover(hulls, surface_samples(link.solid))
    elif not hulls:  # `mesh`, or a decomposition that left nothing: one piece, the hull
        hulls = [_manifold(link.solid).hull()]
    meshes = [convex_mesh(h) for h in hulls]
    order = sorted(range(len(meshes)), key=lambda i: tuple(np.round(meshes[i].vertices.mean(0), 9)))
    hulls, meshes = [hulls[i] for i in order], [meshes[i] for i in order]
    report = {"method": method, **quality(link.solid, hulls)}
    if method == "coacd":
        report["coacd_seed"] = seed
    return tuple(meshes), report
