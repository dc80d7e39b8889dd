"""A link's visuals and collisions (the source model's `Geometry`) to spec primitives (link
frame, metres)."""

from __future__ import annotations

from simkit.importer.diagnostics import Report
from simkit.importer.read.model import Geometry, Link, Shape
from simkit.importer.read.source import MissingMesh, Source, resolve_uri
from simkit.importer.translate.meshes import MeshWriter
from simkit.importer.translate.solids import estimated_box


def placed(xyz, rpy) -> dict:
    """The pose keys of a spec primitive, leaving out zeros."""
    out: dict = {}
    if any(xyz):
        out["xyz"] = list(xyz)
    if any(rpy):
        out["rpy"] = list(rpy)
    return out


#: m: the smallest primitive dimension a spec accepts (spec/bounds.py: radius, length, size)
MIN_SIZE = 1e-3


def _dims(shape: Shape) -> list[float] | None:
    """A box's, cylinder's, capsule's or sphere's sizes (m); None for another shape."""
    if shape.kind == "box":
        return list(shape.size or ())
    if shape.kind == "sphere":
        return [shape.radius]
    if shape.kind in ("cylinder", "capsule"):
        return [shape.radius, shape.length]
    return None


def _too_small(source: Source, shape: Shape, report: Report, what: str) -> bool:
    """A box, cylinder, capsule or sphere with a positive dimension below MIN_SIZE is left out
    with one report line: the spec refuses it (too small to simulate) and it holds no mass
    worth keeping (a 0.5 mm collision sphere on a sensor frame)."""
    flat = _dims(shape)
    if flat is None:
        return False
    small = [v for v in flat if 0 < v < MIN_SIZE]
    if not small or min(flat) <= 0:
        return False  # non-positive sizes have their own line below
    report.dropped(
        source,
        shape.at,
        f"{what} {shape.kind} of {min(small):g} m is below the {MIN_SIZE:g} m "
        "a spec simulates: left out",
    )
    return True


def shape_of(
    source: Source, geometry: Geometry, link: Link, writer: MeshWriter, report: Report, what: str
):
    """One visual/collision of `link` as (spec primitive dict, MeshInfo or None); None if
    left out."""
    shape = geometry.shape
    if shape is None:
        raise source.fail(geometry.at, f"{what} without geometry")
    pose = placed(geometry.origin.xyz, geometry.origin.rpy)
    kind = shape.kind
    if _too_small(source, shape, report, what):
        return None
    if kind == "box":
        size = shape.size
        if min(size) <= 0:
            report.dropped(source, shape.at, f"{what} box with a non-positive size {size}")
            return None
        return {"shape": "box", "size": list(size), **pose}, None
    if kind in ("cylinder", "capsule"):
        radius, length = shape.radius, shape.length
        if radius <= 0 or length <= 0:
            report.dropped(source, shape.at, f"{what} {kind} with radius or length <= 0")
            return None
        return {"shape": kind, "radius": radius, "length": length, **pose}, None
    if kind == "sphere":
        radius = shape.radius
        if radius == 0 and what == "collision":  # a contact point: translate/points.py
            return {"shape": "sphere", "radius": 0.0, **pose}, None
        if radius <= 0:
            report.dropped(source, shape.at, f"{what} sphere with radius <= 0")
            return None
        return {"shape": "sphere", "radius": radius, **pose}, None
    if kind == "mesh":
        return _mesh(source, geometry, link, writer, report, what)
    report.dropped(source, shape.at, f"{what} geometry <{kind}> is not supported")
    return None


def _mesh(
    source: Source, geometry: Geometry, link: Link, writer: MeshWriter, report: Report, what: str
):
    """A mesh geometry written to the staging folder (shape_of)."""
    shape = geometry.shape
    assert shape is not None
    uri = shape.filename
    if not uri:
        raise source.fail(shape.at, "mesh without 'filename'")
    try:
        path = resolve_uri(source, shape.at, uri)
    except MissingMesh as exc:
        return _missing(source, geometry, link, exc.message, what)
    scale = shape.scale
    if min(abs(s) for s in scale) <= 0:
        raise source.fail(shape.at, f"mesh scale must be non-zero, got {scale}")
    try:
        info = writer.write(path, scale)  # type: ignore[arg-type]
    except ValueError as exc:  # present but unreadable: left out, reported
        report.dropped(source, shape.at, f"{what} {uri}: {exc}")
        return None
    pose = placed(geometry.origin.xyz, geometry.origin.rpy)
    return {"shape": "mesh", "file": info.file, **pose}, info


def _missing(source: Source, geometry: Geometry, link: Link, why: str, what: str):
    """A mesh no rule finds: this geometry is left out (as PyBullet does), reported; a link
    left with no geometry at all gets an estimated box instead (importer/translate/solids.py)."""
    shape = geometry.shape
    assert shape is not None
    # the link's other visuals and collisions in document order (as its lines give it): a
    # mesh resolved here first reports its path fallback here
    others = sorted(
        (g for g in (*link.visuals, *link.collisions) if g is not geometry),
        key=lambda g: g.at.sourceline or 0,
    )
    if any(_usable(source, other) for other in others):
        source.lenient(shape.at, f"{why}: this {what} is left out")
        return None
    box = _estimated_box(source, link)
    source.lenient(
        shape.at,
        f"{why}: this {what} is left out; the link has no other geometry, so it gets an "
        f"estimated box {' x '.join(f'{s:g}' for s in box['size'])} m (importer/solids.py)",
    )
    return box, None


def _usable(source: Source, geometry: Geometry) -> bool:
    """Whether a visual/collision has a shape other than a mesh no rule finds."""
    shape = geometry.shape
    if shape is None:
        return False
    if shape.kind != "mesh":
        return True
    try:
        resolve_uri(source, shape.at, shape.filename or "")
    except MissingMesh:
        return False
    except Exception:  # refused or ambiguous: reported when that geometry is read
        return True
    return True


def _estimated_box(source: Source, link: Link) -> dict:
    """The box solids.py gives a geometry-free link: bounding its origin, CoM and child
    joints, holding its mass (or the massless placeholder) at water's density."""
    import numpy as np

    inertial = link.inertial
    mass = inertial.mass if inertial is not None and inertial.mass is not None else 0.0
    points = [(0.0, 0.0, 0.0)]
    if inertial is not None:
        points.append(inertial.origin.xyz)
    for joint in source.robot.joints:
        if joint.parent == link.name:
            points.append(joint.origin.xyz)
    return estimated_box(mass if mass > 0 else 0.001, np.array(points, dtype=float))
