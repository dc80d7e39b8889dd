"""URDF `<visual>` and `<collision>` elements to spec primitives (link frame, metres)."""

from __future__ import annotations

from simkit.importer.diagnostics import Report
from simkit.importer.read.lenient import first_numbers, loose_numbers
from simkit.importer.read.source import MissingMesh, Source, resolve_uri
from simkit.importer.translate.meshes import MeshWriter
from simkit.importer.translate.solids import estimated_box


def floats(source: Source, element, attr: str, count: int, default: str | None = None):
    """`count` floats from a space-separated attribute; one-line error if malformed. A
    longer vector gives its first `count` numbers, read leniently (as PyBullet does)."""
    text = element.get(attr, default)
    if text is None:
        raise source.fail(element, f"missing attribute '{attr}'")
    longer = first_numbers(text, count) if count > 1 else None
    if longer is not None and all(v == v and abs(v) != float("inf") for v in longer):
        source.lenient(
            element, f"'{attr}' has more than {count} numbers ('{text}'): the first {count}"
        )
        return longer
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = loose_numbers(text)
        if values is None:
            raise source.fail(element, f"'{attr}' is not a number list: '{text}'") from None
        shown = " ".join(f"{v:g}" for v in values)
        source.lenient(element, f"'{attr}' is '{text}': read as '{shown}' (as C's strtod reads it)")
    if len(values) != count or any(v != v or abs(v) == float("inf") for v in values):
        raise source.fail(element, f"'{attr}' needs {count} finite numbers, got '{text}'")
    return values if count > 1 else values[0]


def origin(source: Source, parent) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """xyz and rpy of a parent's `<origin>` (zeros when absent)."""
    element = parent.find("origin")
    if element is None:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return floats(source, element, "xyz", 3, "0 0 0"), floats(source, element, "rpy", 3, "0 0 0")


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


def _too_small(source: Source, shape, report: Report, what: str) -> bool:
    """A box, cylinder, capsule or sphere with a positive dimension below MIN_SIZE is left out
    with one report line: the spec refuses it (too small to simulate) and it holds no mass
    worth keeping (a 0.5 mm collision sphere on a sensor frame)."""
    keys = {"box": ("size", 3), "sphere": ("radius", 1), "cylinder": ("radius", 1)}
    keys["capsule"] = keys["cylinder"]
    if shape.tag not in keys:
        return False
    dims = [floats(source, shape, *keys[shape.tag])]
    if shape.tag in ("cylinder", "capsule"):
        dims.append(floats(source, shape, "length", 1))
    flat = [v for d in dims for v in (d if isinstance(d, tuple) else (d,))]
    small = [v for v in flat if 0 < v < MIN_SIZE]
    if not small or min(flat) <= 0:
        return False  # non-positive sizes have their own line below
    report.dropped(
        source,
        shape,
        f"{what} {shape.tag} of {min(small):g} m is below the {MIN_SIZE:g} m "
        "a spec simulates: left out",
    )
    return True


def shape_of(source: Source, element, writer: MeshWriter, report: Report, what: str):
    """One `<visual>`/`<collision>` as (spec primitive dict, MeshInfo or None); None if empty."""
    geometry = element.find("geometry")
    shapes = [] if geometry is None else [g for g in geometry if isinstance(g.tag, str)]
    if not shapes:
        raise source.fail(element, f"{what} without geometry")
    shape = shapes[0]
    xyz, rpy = origin(source, element)
    pose = placed(xyz, rpy)
    kind = shape.tag
    if _too_small(source, shape, report, what):
        return None
    if kind == "box":
        size = floats(source, shape, "size", 3)
        if min(size) <= 0:
            report.dropped(source, shape, f"{what} box with a non-positive size {size}")
            return None
        return {"shape": "box", "size": list(size), **pose}, None
    if kind in ("cylinder", "capsule"):
        radius, length = floats(source, shape, "radius", 1), floats(source, shape, "length", 1)
        if radius <= 0 or length <= 0:
            report.dropped(source, shape, f"{what} {kind} with radius or length <= 0")
            return None
        return {"shape": kind, "radius": radius, "length": length, **pose}, None
    if kind == "sphere":
        radius = floats(source, shape, "radius", 1)
        if radius == 0 and what == "collision":  # a contact point: translate/points.py
            return {"shape": "sphere", "radius": 0.0, **pose}, None
        if radius <= 0:
            report.dropped(source, shape, f"{what} sphere with radius <= 0")
            return None
        return {"shape": "sphere", "radius": radius, **pose}, None
    if kind == "mesh":
        uri = shape.get("filename")
        if not uri:
            raise source.fail(shape, "mesh without 'filename'")
        try:
            path = resolve_uri(source, shape, uri)
        except MissingMesh as exc:
            return _missing(source, element, shape, exc.message, what)
        scale = floats(source, shape, "scale", 3, "1 1 1")
        if min(abs(s) for s in scale) <= 0:
            raise source.fail(shape, f"mesh scale must be non-zero, got {scale}")
        try:
            info = writer.write(path, scale)  # type: ignore[arg-type]
        except ValueError as exc:  # present but unreadable: left out, reported
            report.dropped(source, shape, f"{what} {uri}: {exc}")
            return None
        return {"shape": "mesh", "file": info.file, **pose}, info
    report.dropped(source, shape, f"{what} geometry <{kind}> is not supported")
    return None


def _missing(source: Source, element, shape, why: str, what: str):
    """A mesh no rule finds: this geometry is left out (as PyBullet does), reported; a link
    left with no geometry at all gets an estimated box instead (importer/translate/solids.py)."""
    link = element.getparent()
    if any(_usable(source, other) for other in link if other is not element):
        source.lenient(shape, f"{why}: this {what} is left out")
        return None
    box = _estimated_box(source, link)
    source.lenient(
        shape,
        f"{why}: this {what} is left out; the link has no other geometry, so it gets an "
        f"estimated box {' x '.join(f'{s:g}' for s in box['size'])} m (importer/solids.py)",
    )
    return box, None


def _usable(source: Source, element) -> bool:
    """Whether a `<visual>`/`<collision>` has geometry other than a mesh no rule finds."""
    if element.tag not in ("visual", "collision"):
        return False
    mesh = element.find("geometry/mesh")
    if mesh is None:
        return element.find("geometry") is not None
    try:
        resolve_uri(source, mesh, mesh.get("filename") or "")
    except MissingMesh:
        return False
    except Exception:  # refused or ambiguous: reported when that element is read
        return True
    return True


def _estimated_box(source: Source, link) -> dict:
    """The box solids.py gives a geometry-free link: bounding its origin, CoM and child
    joints, holding its mass (or the massless placeholder) at water's density."""
    import numpy as np

    mass_el = link.find("inertial/mass")
    try:
        mass = float(mass_el.get("value", "0")) if mass_el is not None else 0.0
    except ValueError:
        mass = 0.0
    points = [(0.0, 0.0, 0.0)]
    inertial = link.find("inertial")
    if inertial is not None:
        points.append(origin(source, inertial)[0])
    for joint in source.root.findall("joint"):
        parent = joint.find("parent")
        if parent is not None and parent.get("link") == link.get("name"):
            points.append(origin(source, joint)[0])
    return estimated_box(mass if mass > 0 else 0.001, np.array(points, dtype=float))
