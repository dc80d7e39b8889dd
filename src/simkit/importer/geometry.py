"""URDF `<visual>` and `<collision>` elements to spec primitives (link frame, metres)."""

from __future__ import annotations

from simkit.importer.meshes import MeshWriter
from simkit.importer.report import Report
from simkit.importer.source import Source, resolve_uri


def floats(source: Source, element, attr: str, count: int, default: str | None = None):
    """`count` floats from a space-separated attribute; one-line error if malformed."""
    text = element.get(attr, default)
    if text is None:
        raise source.fail(element, f"missing attribute '{attr}'")
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        raise source.fail(element, f"'{attr}' is not a number list: '{text}'") from None
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
        if radius <= 0:
            report.dropped(source, shape, f"{what} sphere with radius <= 0")
            return None
        return {"shape": "sphere", "radius": radius, **pose}, None
    if kind == "mesh":
        uri = shape.get("filename")
        if not uri:
            raise source.fail(shape, "mesh without 'filename'")
        path = resolve_uri(source, shape, uri)
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
