"""A source model a reader computed (a compiled MJCF, SDFormat's frames, a USD stage), its
numbers refused where one is not finite, as the URDF reader refuses such text
(formats/urdf/model.py `floats`): one line at the first such node, in the order that reader
reads a document (materials, then each link's inertial, visuals and collisions, then each
joint), in its words. A mass that is not positive (NaN included) is no mass, so its inertia
is not read, as there. `formats.load` runs it on every model a reader built itself.
"""

from __future__ import annotations

import math

from simkit.importer.read.model import At, Geometry, Pose, Robot

INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
#: where a material's rgba is (the document's `<color>`, which the model does not keep)
COLOR = At("color")


def check(source, robot: Robot) -> Robot:
    """`robot`, once every number the translation reads is finite; else `source.fail`."""

    def numbers(at, attr: str, values) -> None:
        values = values if isinstance(values, tuple) else (values,)
        if not all(math.isfinite(v) for v in values):
            text = " ".join(repr(float(v)) for v in values)
            raise source.fail(at, f"'{attr}' needs {len(values)} finite numbers, got '{text}'")

    def pose(p: Pose) -> None:
        numbers(p.at, "xyz", p.xyz)
        numbers(p.at, "rpy", p.rpy)

    def geometry(g: Geometry) -> None:
        pose(g.origin)
        shape = g.shape
        for attr in ("size", "radius", "length"):
            if shape is not None and getattr(shape, attr) is not None:
                numbers(shape.at, attr, getattr(shape, attr))
        if g.material is not None and g.material.rgba is not None:
            numbers(COLOR, "rgba", g.material.rgba)

    for material in robot.materials:
        numbers(COLOR, "rgba", material.rgba)
    for link in robot.links:
        inertial = link.inertial
        if inertial is not None:  # the reader reads the mass and inertia before the origin
            if inertial.massive:
                numbers(inertial.mass_at, "value", inertial.mass)
            for key, value in zip(INERTIA_KEYS, inertial.inertia or (), strict=False):
                numbers(inertial.inertia_at, key, value)
            pose(inertial.origin)
        for g in link.visuals + link.collisions:
            geometry(g)
    for joint in robot.joints:
        _joint(joint, pose, numbers)
    return robot


def _joint(joint, pose, numbers) -> None:
    """A joint's origin, axis, limits, dynamics and mimic, in the URDF reader's order."""
    pose(joint.origin)
    if joint.axis is not None:
        numbers(joint.axis_at, "xyz", joint.axis)
    if joint.limit is not None:
        for key in ("effort", "velocity", "lower", "upper"):
            value = getattr(joint.limit, key)
            if value is not None:
                numbers(joint.limit.at, key, value)
    if joint.dynamics is not None:
        for key in ("damping", "friction"):
            numbers(joint.dynamics.at, key, getattr(joint.dynamics, key))
    if joint.mimic is not None:
        numbers(joint.mimic.at, "multiplier", joint.mimic.multiplier)
        numbers(joint.mimic.at, "offset", joint.mimic.offset)
