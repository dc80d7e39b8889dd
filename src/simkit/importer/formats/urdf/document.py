"""The source model (importer/read/model.py) written as a URDF document (lxml), numbers as
the shortest text that reads back exactly (`repr`).

The inverse of formats/urdf/model.py for what the model holds: `robot_of` of the written
document is the model again (its places aside). Proofs that hand the model to another
reader (Drake's URDF parser, in the SDFormat proof's tests) write it so.
"""

from __future__ import annotations

from simkit.importer.read.model import Geometry, Inertial, Joint, Link, Pose, Robot

INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")


def text(values) -> str:
    """Numbers as the shortest text that reads back exactly."""
    if isinstance(values, (int, float)):
        return repr(float(values))
    return " ".join(repr(float(v)) for v in values)


def document(robot: Robot):
    """The `<robot>` element of the model: links, then joints, in the model's order."""
    from lxml import etree

    root = etree.Element("robot", name=robot.name or "robot")
    for link in robot.links:
        _link(etree.SubElement(root, "link", name=link.name), link)
    for joint in robot.joints:
        _joint(etree.SubElement(root, "joint", name=joint.name or "", type=joint.type), joint)
    return root


def _add(parent, tag: str, attrs: dict | None = None):
    """A child element; attributes whose value is None are left out."""
    values = {k: v if isinstance(v, str) else text(v) for k, v in (attrs or {}).items()}
    return parent.makeelement(tag, {k: v for k, v in values.items() if v != "None"})


def _child(parent, tag: str, **attrs):
    element = _add(parent, tag, {k: v for k, v in attrs.items() if v is not None})
    parent.append(element)
    return element


def _origin(parent, pose: Pose) -> None:
    if pose.at is not None or any(pose.xyz) or any(pose.rpy):
        _child(parent, "origin", xyz=pose.xyz, rpy=pose.rpy)


def _link(element, link: Link) -> None:
    if link.inertial is not None:
        _inertial(_child(element, "inertial"), link.inertial)
    for tag, geometries in (("visual", link.visuals), ("collision", link.collisions)):
        for geometry in geometries:
            _geometry(_child(element, tag), geometry)


def _inertial(element, inertial: Inertial) -> None:
    _origin(element, inertial.origin)
    if inertial.mass is not None:
        _child(element, "mass", value=inertial.mass)
    if inertial.inertia is not None:
        _child(element, "inertia", **dict(zip(INERTIA_KEYS, inertial.inertia, strict=True)))


def _geometry(element, geometry: Geometry) -> None:
    _origin(element, geometry.origin)
    shape = geometry.shape
    if shape is not None:
        sizes = {k: getattr(shape, k) for k in ("size", "radius", "length")}
        if shape.kind == "mesh":
            sizes.update(filename=shape.filename or "", scale=shape.scale)
        _child(_child(element, "geometry"), shape.kind, **sizes)
    material = geometry.material
    if material is not None:
        tag = _child(element, "material", name=material.name or "")
        if material.rgba is not None:
            _child(tag, "color", rgba=material.rgba)


def _joint(element, joint: Joint) -> None:
    _origin(element, joint.origin)
    _child(element, "parent", link=joint.parent)
    _child(element, "child", link=joint.child)
    if joint.axis is not None:
        _child(element, "axis", xyz=joint.axis)
    if joint.limit is not None:
        keys = ("lower", "upper", "effort", "velocity", "twist")
        _child(element, "limit", **{k: getattr(joint.limit, k) for k in keys})
    if joint.dynamics is not None:
        _child(
            element, "dynamics", damping=joint.dynamics.damping, friction=joint.dynamics.friction
        )
    if joint.mimic is not None:
        mimic = joint.mimic
        _child(
            element, "mimic", joint=mimic.joint, multiplier=mimic.multiplier, offset=mimic.offset
        )
