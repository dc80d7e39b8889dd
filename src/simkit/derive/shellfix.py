"""Make a welded triangle mesh a manifold by index again, for Open CASCADE.

The STEP writer (brep.py) welds vertices closer than its tolerance, because Open CASCADE
cannot make an edge shorter than 1e-7 mm. On a CAD mesh full of slivers, or a solid that
touches itself along an edge (two sheets pinched together), welding leaves edges that more
than two triangles share. A faceted shell with such an edge fails BRepCheck, and the link
has no valid STEP solid. Here each such edge's triangles are paired by the solid's side,
and a vertex whose triangles then fall into separate fans gets one copy per fan: the same
surface, now a manifold by index, as Open CASCADE's mesh builder wants.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np

from simkit.model.robot import edge_uses


def over_shared(triangles: np.ndarray) -> bool:
    """True when an edge is shared by more than two triangles."""
    return bool(len(triangles)) and int(edge_uses(triangles).max()) > 2


def unpinched(points: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """`points` (with copies appended) and `triangles` re-indexed so that every edge has at
    most two triangles. Pairs of triangles with the same corners and opposite windings (a
    zero-thickness fin) are dropped first: they enclose nothing."""
    triangles = _without_fins(triangles)
    joined = _joins(points, triangles)
    corners: dict[int, list[int]] = defaultdict(list)
    for t, tri in enumerate(triangles.tolist()):
        for v in tri:
            corners[v].append(t)
    out = triangles.copy()
    extra: list[np.ndarray] = []
    for vertex in sorted(corners):
        for fan in _fans(vertex, corners[vertex], triangles, joined)[1:]:
            copy = len(points) + len(extra)
            extra.append(points[vertex])
            for t in fan:
                out[t][out[t] == vertex] = copy
    if extra:
        points = np.vstack([points, np.array(extra)])
    return points, out


def _without_fins(triangles: np.ndarray) -> np.ndarray:
    """The triangles less each pair with the same corners and opposite winding."""
    keys: dict[tuple[int, ...], list[int]] = defaultdict(list)
    for t, tri in enumerate(triangles.tolist()):
        keys[tuple(sorted(tri))].append(t)
    drop: set[int] = set()
    for group in keys.values():
        ups = [t for t in group if _even(triangles[t])]
        downs = [t for t in group if not _even(triangles[t])]
        for up, down in zip(ups, downs, strict=False):
            drop.update((up, down))
    return triangles[[t for t in range(len(triangles)) if t not in drop]]


def _even(tri: np.ndarray) -> bool:
    """True when the triangle's corners are an even turn of their sorted order."""
    a, b, c = tri.tolist()
    return (a < b < c) or (b < c < a) or (c < a < b)


def _joins(points: np.ndarray, triangles: np.ndarray) -> set[tuple[int, int, int, int]]:
    """(edge start, edge end, triangle, triangle): the triangle pairs joined across each
    edge. A shared-by-two edge joins its two; a more-shared edge joins each triangle that
    runs a->b to the one beside it on the solid's inner side (turning about a->b)."""
    users: dict[tuple[int, int], list[int]] = defaultdict(list)
    for t, tri in enumerate(triangles.tolist()):
        for i in range(3):
            a, b = tri[i], tri[(i + 1) % 3]
            users[(min(a, b), max(a, b))].append(t)
    joined: set[tuple[int, int, int, int]] = set()
    for (a, b), ts in users.items():
        pairs = [tuple(ts)] if len(ts) == 2 else _paired(points, triangles, a, b, ts)
        for s, t in pairs:
            joined.add((a, b, min(s, t), max(s, t)))
    return joined


def _paired(points, triangles, a: int, b: int, ts: list[int]) -> list[tuple[int, int]]:
    """Around edge a-b, sorted by the angle of each triangle's third corner: a triangle that
    runs a->b has its outward normal toward larger angles, so the solid lies toward smaller
    ones, and it pairs with the triangle just before it."""
    axis = points[b] - points[a]
    axis = axis / (np.linalg.norm(axis) or 1.0)
    u = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(axis, u)

    def angle(t: int) -> float:
        third = next(v for v in triangles[t].tolist() if v not in (a, b))
        d = points[third] - points[a]
        return math.atan2(float(d @ w), float(d @ u))

    order = sorted(ts, key=lambda t: (angle(t), t))
    pairs = []
    for k, t in enumerate(order):
        if _runs(triangles[t], a, b):
            pairs.append((t, order[k - 1]))
    return pairs


def _runs(tri: np.ndarray, a: int, b: int) -> bool:
    """True when the triangle's winding goes from a to b."""
    corners = tri.tolist()
    return corners[(corners.index(a) + 1) % 3] == b


def _fans(vertex: int, around: list[int], triangles, joined) -> list[list[int]]:
    """The triangles at `vertex` grouped by the joins across edges at that vertex."""
    group = {t: t for t in around}

    def root(t: int) -> int:
        while group[t] != t:
            group[t] = group[group[t]]
            t = group[t]
        return t

    for s in around:
        for other in triangles[s].tolist():
            if other == vertex:
                continue
            a, b = min(vertex, other), max(vertex, other)
            for t in around:
                if t > s and (a, b, s, t) in joined:
                    group[root(t)] = root(s)
    fans: dict[int, list[int]] = defaultdict(list)
    for t in around:
        fans[root(t)].append(t)
    return sorted(fans.values(), key=min)


def without_needles(points: np.ndarray, triangles: np.ndarray, height: float) -> np.ndarray:
    """The triangles with needles flipped away, pass after pass while one flips: a needle
    has a corner closer than `height` (mm) to its longest edge, so no plane Open CASCADE
    can fit (it drops that face and the shell is open)."""
    out = [list(t) for t in triangles.tolist()]
    for _ in range(8):
        if not _flip_pass(points, out, height):
            break
    return np.array(out, dtype=triangles.dtype).reshape(-1, 3)


def _flip_pass(points: np.ndarray, out: list[list[int]], height: float) -> int:
    """Flip each needle a-b-c (a-b its longest edge) with the triangle across that edge,
    b-a-d, into c-a-d and c-d-b: the same surface. A flip that would repeat an edge or make
    another needle is skipped. The number flipped."""
    across = {(t[i], t[(i + 1) % 3]): k for k, t in enumerate(out) for i in range(3)}
    flipped = 0
    for k in range(len(out)):
        a, b, c = _longest_first(points, out[k])
        if _height(points, a, b, c) >= height or (b, a) not in across:
            continue
        other = across[(b, a)]
        d = next(v for v in out[other] if v not in (a, b))
        new = ([c, a, d], [c, d, b])
        if (c, d) in across or (d, c) in across or d == c:
            continue
        if min(_height(points, *_longest_first(points, t)) for t in new) < height:
            continue
        for t in (out[k], out[other]):
            for i in range(3):
                across.pop((t[i], t[(i + 1) % 3]), None)
        out[k], out[other] = new
        for n in (k, other):
            for i in range(3):
                across[(out[n][i], out[n][(i + 1) % 3])] = n
        flipped += 1
    return flipped


def _longest_first(points: np.ndarray, tri: list[int]) -> tuple[int, int, int]:
    """The triangle's corners turned so that a-b is its longest edge (winding kept)."""
    turns = [tuple(tri[i:] + tri[:i]) for i in range(3)]
    return max(turns, key=lambda t: float(np.linalg.norm(points[t[1]] - points[t[0]])))


def _height(points: np.ndarray, a: int, b: int, c: int) -> float:
    """mm from corner c to the line through a and b."""
    base = points[b] - points[a]
    length = float(np.linalg.norm(base))
    cross = float(np.linalg.norm(np.cross(base, points[c] - points[a])))
    return cross / length if length else 0.0
