"""The source model (importer/read/model.py) written as a URDF document (lxml), numbers as
the shortest text that reads back exactly (`repr`).

The inverse of formats/urdf/model.py for what the model holds: `robot_of` of the written
document is the model again (its places aside). Proofs that hand the model to another
reader (Drake's URDF parser, in the SDFormat proof's tests) write it so.
"""

from __future__ import annotations

from simkit.importer.read.model import Geometry, Inertial, Joint, Link, Material, Pose, Robot

INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")


def text(values) -> str:
    """Numbers as the shortest text that reads back exactly."""
    if isinstance(values, (int, float)):
        return repr(float(values))
    return " ".join(repr(float(v)) for v in values)


def document(robot: Robot):
    """The `<robot>` element of the model: links, then joints, in the model's order, each
    element on its node's source line (`At.sourceline`)."""
    from lxml import etree

    root = etree.Element("robot", name=robot.name or "robot")
    _line(root, robot.at)
    drawn = {g.material.at for link in robot.links for g in link.visuals if g.material}
    for material in robot.materials:  # the named ones no visual holds: top level
        if material.at not in drawn:
            _material(root, material)
    for link in robot.links:
        _link(_child(root, "link", link.at, name=link.name), link)
    for joint in robot.joints:
        _joint(_child(root, "joint", joint.at, name=joint.name or "", type=joint.type), joint)
    _unread(root, robot.others)
    return root


def _unread(parent, places) -> None:
    """The elements the model only places (unread children, other top-level elements), as
    empty elements with their tag and name: the report names them."""
    for at in places:
        _child(parent, at.tag, at, name=at.name)


def _child(parent, tag: str, at=None, **attrs):
    """A child element, its source line `at`'s (an `At`; None: its parent's); attributes
    whose value is None are left out, numbers written by `text`."""
    values = {k: v if isinstance(v, str) else text(v) for k, v in attrs.items() if v is not None}
    element = parent.makeelement(tag, values)
    parent.append(element)
    _line(element, at if at is not None else parent)
    return element


def _line(element, at) -> None:
    """The element takes the line of `at` (an At or element) where one is known, so report
    lines about a written document name the source's lines."""
    line = getattr(at, "sourceline", None)
    if line is not None:
        element.sourceline = line


def _origin(parent, pose: Pose) -> None:
    if pose.at is not None or any(pose.xyz) or any(pose.rpy):
        _child(parent, "origin", pose.at, xyz=pose.xyz, rpy=pose.rpy)


def _link(element, link: Link) -> None:
    if link.inertial is not None:
        _inertial(_child(element, "inertial", link.inertial.at), link.inertial)
    for tag, geometries in (("visual", link.visuals), ("collision", link.collisions)):
        for geometry in geometries:
            _geometry(_child(element, tag, geometry.at, name=geometry.at.name), geometry)
    _unread(element, link.unknown)


def _inertial(element, inertial: Inertial) -> None:
    _origin(element, inertial.origin)
    if inertial.mass is not None:
        _child(element, "mass", inertial.mass_at, value=inertial.mass)
    if inertial.inertia_at is not None:  # a massless link's inertia is not read: empty
        values = dict(zip(INERTIA_KEYS, inertial.inertia or (None,) * 6, strict=True))
        _child(element, "inertia", inertial.inertia_at, **values)


def _geometry(element, geometry: Geometry) -> None:
    _origin(element, geometry.origin)
    shape = geometry.shape
    if shape is not None:
        sizes = {k: getattr(shape, k) for k in ("size", "radius", "length")}
        if shape.kind == "mesh":
            sizes.update(filename=shape.filename or "", scale=shape.scale)
        _child(_child(element, "geometry", shape.at), shape.kind, shape.at, **sizes)
    if geometry.material is not None:
        _material(element, geometry.material)


def _material(parent, material: Material) -> None:
    tag = _child(parent, "material", material.at, name=material.name)
    if material.rgba is not None:
        _child(tag, "color", rgba=material.rgba)


def _joint(element, joint: Joint) -> None:
    _origin(element, joint.origin)
    _child(element, "parent", link=joint.parent)
    _child(element, "child", link=joint.child)
    if joint.axis is not None:
        _child(element, "axis", joint.axis_at, xyz=joint.axis)
    limit = joint.limit
    if limit is not None:
        keys = ("lower", "upper", "effort", "velocity", "twist")
        _child(element, "limit", limit.at, **{k: getattr(limit, k) for k in keys})
    dynamics = joint.dynamics
    if dynamics is not None:
        _child(
            element, "dynamics", dynamics.at, damping=dynamics.damping, friction=dynamics.friction
        )
    mimic = joint.mimic
    if mimic is not None:
        numbers = {"multiplier": mimic.multiplier, "offset": mimic.offset}
        _child(element, "mimic", mimic.at, joint=mimic.joint, **numbers)
    _unread(element, joint.unknown)
