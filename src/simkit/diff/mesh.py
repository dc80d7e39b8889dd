"""`simkit diff` for meshes: each STL or OBJ compared as a placed piece in its link frame.

A kit's meshes sit at the identity in their link frame (the URDF's <origin> is zero), so the
vertices are link-frame positions. Each change is classed before it is described (issue 34):

- rigid: one rigid motion carries the old surface onto the new within the length rule; the
  piece moved (its volume centroid) and turned (the motion's angle);
- scaled: one similarity does; the scale factor, and the volume and bounding box it changes;
- changed shape: no motion does, and none is fitted: the largest distance between the old and
  new surfaces (symmetric Hausdorff, sampled: `surface`), the volume, the bounding box, and
  the region that changed (the bounding box of the points off the other surface).

A fit is only a candidate (through the corners when both files have as many triangles, about
the area centroids, along the principal axes), kept when the surfaces verify it. A new
triangulation of the same surface is not a change.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import NamedTuple

import numpy as np

from simkit.diff.report import Change
from simkit.diff.surface import (
    Gap,
    Mesh,
    Similarity,
    gap,
    principal_axes,
    same_vertices,
    similarity,
    surface_centroid,
    within,
)
from simkit.diff.tolerance import ANGLE_RAD, LENGTH_M, REL
from simkit.errors import SimkitError
from simkit.kitio.obj import read_mesh

#: proper rotations that match two sets of principal axes whose signs are arbitrary
AXIS_SIGNS = ((1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1))


class Piece(NamedTuple):
    """A mesh's placement and size in its link frame (m, m^2, m^3)."""

    vertices: np.ndarray
    faces: np.ndarray
    volume: float
    area: float
    centroid: np.ndarray
    low: np.ndarray
    high: np.ndarray
    #: the surface, for distances to it
    mesh: Mesh


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
        return Piece(v, faces, 0.0, 0.0, zero, zero, zero, Mesh(v, faces))
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
    low, high = v.min(axis=0), v.max(axis=0)
    return Piece(v, faces, volume, area, centroid, low, high, Mesh(v, faces))


def _refined(fit: Similarity, a: Piece, b: Piece) -> Similarity:
    """`fit` redone through each moved vertex of `a` and its nearest vertex of `b`: a fit
    from moments is good to float32 round-off only, the pairs make it exact where the two
    meshes share their vertices (scipy, lazily)."""
    _gaps, nearest = b.mesh.tree.query(fit.apply(a.vertices))
    return similarity(a.vertices, b.vertices[nearest], scaled=fit.scale != 1.0)


def _candidates(a: Piece, b: Piece) -> Iterator[Similarity]:
    """Similarities worth verifying, cheapest first; rigid ones before scaled ones."""
    if len(a.faces) == len(b.faces):
        ca, cb = a.vertices[a.faces].reshape(-1, 3), b.vertices[b.faces].reshape(-1, 3)
        yield similarity(ca, cb, scaled=False)
        yield similarity(ca, cb, scaled=True)
    (area_a, centre_a), (area_b, centre_b) = surface_centroid(a.mesh), surface_centroid(b.mesh)
    scales = [1.0] + ([math.sqrt(area_b / area_a)] if area_a > 0 and area_b > 0 else [])
    axes_a, axes_b = principal_axes(a.mesh), principal_axes(b.mesh)
    turns = [np.eye(3)] + [axes_b @ np.diag(s) @ axes_a.T for s in AXIS_SIGNS]
    for scale in scales:
        for rot in turns:
            if np.linalg.det(rot) > 0:
                fit = Similarity(scale, rot, centre_b - scale * rot @ centre_a)
                yield fit
                yield _refined(fit, a, b)


def motion(a: Piece, b: Piece) -> Similarity | None:
    """The first candidate similarity whose image of `a` is `b` within the length rule
    (`surface.within`); None when no similarity carries one surface onto the other."""
    tried: list[np.ndarray] = []
    box = np.array([a.low, a.high])
    for fit in _candidates(a, b):
        corners = fit.apply(box)  # a fit that moves the box as a tried one did is that one
        if any(np.abs(corners - seen).max() <= LENGTH_M for seen in tried):
            continue
        tried.append(corners)
        if within(Mesh(fit.apply(a.vertices), a.faces), b.mesh, LENGTH_M):
            return fit
    return None


def _radius(p: Piece) -> float:
    """The piece's extent about its centroid (m): an angle or a scale times it is a length."""
    return float(np.linalg.norm(p.vertices - p.centroid, axis=1).max())


def _volume_row(a: Piece, b: Piece) -> list[tuple]:
    tol = LENGTH_M * max(a.area, b.area)
    if abs(b.volume - a.volume) > tol + REL * abs(a.volume):
        return [("volume", a.volume, b.volume, "m^3", tol)]
    return []


def _bbox_row(a: Piece, b: Piece) -> list[tuple]:
    old, new = [*a.low, *a.high], [*b.low, *b.high]
    if np.abs(np.subtract(new, old)).max() > LENGTH_M:
        return [("bbox", [float(v) for v in old], [float(v) for v in new], "m", LENGTH_M)]
    return []


def _moved(fit: Similarity, a: Piece, b: Piece) -> list[tuple]:
    """Rows of a rigid or scaled piece: displacement, rotation, scale (and what scaling
    changes: volume, bounding box)."""
    out = []
    radius = max(_radius(a), LENGTH_M)
    if float(np.linalg.norm(b.centroid - a.centroid)) > LENGTH_M:
        out.append(("displacement", a.centroid.tolist(), b.centroid.tolist(), "m", LENGTH_M))
    angle = float(np.arccos(np.clip((np.trace(fit.rotation) - 1) / 2, -1.0, 1.0)))
    if angle * radius > LENGTH_M:  # shown at the angle that moves the piece by the rule
        out.append(("rotation", 0.0, angle, "rad", min(ANGLE_RAD, LENGTH_M / radius)))
    if abs(fit.scale - 1) * radius > LENGTH_M:
        out.append(("scale", 1.0, fit.scale, "", LENGTH_M / radius))
        out += _volume_row(a, b) + _bbox_row(a, b)
    return out


def _reshaped(found: Gap, a: Piece, b: Piece) -> list[tuple]:
    """Rows of a changed shape: how far apart the surfaces are, and where; volume, box."""
    out = [("shape", None, found.distance, "m", LENGTH_M)]
    out += _volume_row(a, b) + _bbox_row(a, b)
    if found.region is not None:
        low, high = found.region
        out.append(("region", None, [*map(float, low), *map(float, high)], "m", LENGTH_M))
    if len(a.faces) != len(b.faces):
        out.append(("triangles", len(a.faces), len(b.faces), "", 0.0))
    return out


def mesh_changes(path: str, old: bytes, new: bytes) -> list[Change]:
    """Every change of one mesh beyond the length rule, classed rigid, scaled or changed
    shape; nothing for the same surface, however triangulated."""
    a, b = piece(path, old), piece(path, new)
    finite = [bool(np.all(np.isfinite(p.vertices))) for p in (a, b)]
    if not all(finite):  # a hostile or damaged file: say so, compare nothing
        state = ["finite" if f else "non-finite" for f in finite]
        rows = [("vertices", *state, "", 0.0)] if finite[0] or old != new else []
    elif not (len(a.faces) and len(b.faces)):
        rows = [("triangles", len(a.faces), len(b.faces), "", 0.0)] if old != new else []
    else:
        rows = _rows(a, b)
    return [Change("mesh", path, "modified", *row) for row in rows]


def _rows(a: Piece, b: Piece) -> list[tuple]:
    """(field, old, new, unit, tolerance) rows of two finite, non-empty pieces."""
    if len(a.faces) == len(b.faces):
        ca, cb = a.vertices[a.faces], b.vertices[b.faces]
        if float(np.abs(ca - cb).max()) <= LENGTH_M:
            return []
    if same_vertices(a.mesh, b.mesh, LENGTH_M):
        return []
    fit = motion(a, b)  # an unchanged surface verifies the centroid fit with no turn: no rows
    if fit is not None:
        return _moved(fit, a, b)
    found = gap(a.mesh, b.mesh, LENGTH_M)
    return _reshaped(found, a, b) if found.distance > LENGTH_M else []
