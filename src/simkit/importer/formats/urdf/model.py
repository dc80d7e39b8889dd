"""A URDF document (lxml) to the source model (importer/read/model.py): each number read once.

Numbers are read as URDF readers read them: a space-separated list; a longer list gives its
first numbers and commas or stray trailing dots read as C's strtod reads them (PyBullet),
each one report line (`Source.lenient`, refused with `--strict`); anything else is refused
in one line naming the file, line, element and attribute. What the translation never uses
is not read, so it cannot refuse a file: the inertia of a massless link, the axis, limits,
dynamics and mimic of a joint that does not move, a fixed or continuous joint's position
limits, a spherical joint's axis (PyBullet ignores it). A `<mass>` that is no number
reads as massless (as urdfdom's bodies without mass).

The URDF and xacro readers read their document here. The MJCF, SDFormat and USD readers
build the model themselves from their own data (formats/finite.py then refuses a computed
number that is not finite); `document.py` writes a model back as a URDF document.
"""

from __future__ import annotations

import math

from simkit.importer.read.lenient import first_numbers, loose_numbers
from simkit.importer.read.model import (
    At,
    Dynamics,
    Geometry,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Mimic,
    Pose,
    Robot,
    Shape,
)
from simkit.importer.read.source import Source

TOP = ("link", "joint", "material")
LINK_KEEPS = {"inertial", "visual", "collision"}
JOINT_KEEPS = {"origin", "parent", "child", "axis", "limit", "dynamics", "mimic"}
#: the joint types whose axis, limits, dynamics and mimic the translation reads
MOVING = {"revolute", "continuous", "prismatic", "spherical"}
#: the shapes the translation reads, and the attributes each must give (count of numbers)
SIZES = {
    "box": (("size", 3),),
    "cylinder": (("radius", 1), ("length", 1)),
    "capsule": (("radius", 1), ("length", 1)),
    "sphere": (("radius", 1),),
}


def floats(source: Source, element, attr: str, count: int, default: str | None = None):
    """`count` floats from a space-separated attribute (a float when `count` is 1); one-line
    error if malformed. A longer list gives its first `count` numbers, read leniently."""
    text = element.get(attr, default)
    if text is None:
        raise source.fail(element, f"missing attribute '{attr}'")
    longer = first_numbers(text, count) if count > 1 else None
    if longer is not None and all(math.isfinite(v) for v in longer):
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
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise source.fail(element, f"'{attr}' needs {count} finite numbers, got '{text}'")
    return values if count > 1 else values[0]


def _optional(source: Source, element, attr: str) -> float | None:
    """One number, None when the attribute is not given."""
    return None if element.get(attr) is None else floats(source, element, attr, 1)


def pose(source: Source, parent) -> Pose:
    """The parent's `<origin>` (zeros, `at` None, when absent)."""
    element = parent.find("origin")
    if element is None:
        return Pose()
    xyz = floats(source, element, "xyz", 3, "0 0 0")
    return Pose(xyz, floats(source, element, "rpy", 3, "0 0 0"), At.of(element))


def robot_of(source: Source) -> Robot:
    """The model of `source.root` (a `<robot>`)."""
    root = source.root
    materials = tuple(
        _material(source, m) for m in root.iter("material") if m.find("color") is not None
    )
    return Robot(
        At.of(root),
        root.get("name"),
        tuple(link_of(source, e) for e in root.findall("link")),
        tuple(joint_of(source, e) for e in root.findall("joint")),
        tuple(m for m in materials if m.name),
        tuple(At.of(e) for e in root if isinstance(e.tag, str) and e.tag not in TOP),
    )


def link_of(source: Source, element) -> Link:
    """A `<link>`."""
    unknown = tuple(At.of(e) for e in element if isinstance(e.tag, str) and e.tag not in LINK_KEEPS)
    return Link(
        element.get("name"),
        At.of(element),
        _inertial(source, element.find("inertial")),
        tuple(_geometry(source, e, True) for e in element.findall("visual")),
        tuple(_geometry(source, e, False) for e in element.findall("collision")),
        unknown,
    )


def _inertial(source: Source, element) -> Inertial | None:
    if element is None:
        return None
    mass_el = element.find("mass")
    mass = None
    if mass_el is not None:
        try:
            mass = float(mass_el.get("value", "0"))
        except ValueError:
            mass = None
    if mass is not None and mass > 0:
        mass = floats(source, mass_el, "value", 1)  # refuses an infinite one
    tag = element.find("inertia")
    inertia = None
    if tag is not None and mass is not None and mass > 0:
        keys = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
        inertia = tuple(floats(source, tag, k, 1, "0") for k in keys)
    return Inertial(
        At.of(element),
        pose(source, element),
        mass,
        None if mass_el is None else At.of(mass_el),
        inertia,  # type: ignore[arg-type]
        None if tag is None else At.of(tag),
    )


def _geometry(source: Source, element, visual: bool) -> Geometry:
    geometry = element.find("geometry")
    shapes = [] if geometry is None else [g for g in geometry if isinstance(g.tag, str)]
    material = element.find("material") if visual else None
    return Geometry(
        At.of(element),
        pose(source, element),
        _shape(source, shapes[0]) if shapes else None,
        None if material is None else _material(source, material),
    )


def _shape(source: Source, element) -> Shape:
    kind = str(element.tag)
    values = {key: floats(source, element, key, count) for key, count in SIZES.get(kind, ())}
    if kind == "mesh":
        values["filename"] = element.get("filename")
        values["scale"] = floats(source, element, "scale", 3, "1 1 1")
    return Shape(kind, At.of(element), **values)


def _material(source: Source, element) -> Material:
    colour = element.find("color")
    rgba = None if colour is None else floats(source, colour, "rgba", 4)
    return Material(At.of(element), element.get("name"), rgba)


def joint_of(source: Source, element) -> Joint:
    """A `<joint>`; its axis, limits, dynamics and mimic only where it moves."""
    ends = [element.find(end) for end in ("parent", "child")]
    parent, child = (None if e is None else e.get("link") for e in ends)
    kind = element.get("type", "")
    unknown = tuple(
        At.of(e) for e in element if isinstance(e.tag, str) and e.tag not in JOINT_KEEPS
    )
    origin = pose(source, element)  # read before the rest, as the document gives them
    moving: dict = {}
    if kind in MOVING:
        axis = None if kind == "spherical" else element.find("axis")  # PyBullet ignores it
        moving = {
            "axis": None if axis is None else floats(source, axis, "xyz", 3, "1 0 0"),
            "axis_at": None if axis is None else At.of(axis),
            "limit": _limit(source, element.find("limit"), kind),
            "dynamics": _dynamics(source, element.find("dynamics")),
            "mimic": _mimic(source, element.find("mimic")),
        }
    at = At.of(element)
    return Joint(element.get("name"), kind, at, parent, child, origin, unknown=unknown, **moving)


def _limit(source: Source, element, kind: str) -> Limit | None:
    if element is None:
        return None
    keys = ["effort", "velocity"]
    if kind != "continuous":
        keys += ["lower", "upper"]
    if kind == "spherical":
        keys.append("twist")
    return Limit(At.of(element), **{k: _optional(source, element, k) for k in keys})


def _dynamics(source: Source, element) -> Dynamics | None:
    if element is None:
        return None
    return Dynamics(
        At.of(element),
        _optional(source, element, "damping"),
        _optional(source, element, "friction"),
    )


def _mimic(source: Source, element) -> Mimic | None:
    if element is None:
        return None
    return Mimic(
        At.of(element),
        element.get("joint"),
        floats(source, element, "multiplier", 1, "1"),
        floats(source, element, "offset", 1, "0"),
    )
