"""An SDF universal joint as two revolute joints (a kit's joints turn about one axis each).

SDFormat's universal joint turns its child about `<axis>` (fixed in the parent), then about
`<axis2>` (carried by the first turn), the two axes perpendicular, through the joint frame's
origin. Drake reads it so too: its joint frames are the SDF joint frame turned so that x is
`<axis>` and y is `<axis2>`, and it turns Rx(q1) Ry(q2). The kit takes that frame (`turned`)
as the child link's frame, and the chain: `NAME_1` about x (the `<axis>` limits) into a
massless link `NAME_link`, then `NAME` about y (the `<axis2>` limits) into the child; both
added elements are listed in the spec's source differences.
"""

from __future__ import annotations

import numpy as np

from simkit.importer.formats.sdf.elements import axis_in_joint, in_model, limits, origin
from simkit.importer.formats.sdf.frames import inverse, transform
from simkit.importer.read.model import At, Joint, Link

#: |cos| between the two axes above which they are not perpendicular
PERPENDICULAR = 1e-6


def axes(model, name: str, joint) -> tuple[np.ndarray, np.ndarray]:
    """The two unit axes in the joint frame; one line when they are not perpendicular."""
    x_joint = model.frames.in_model(name, joint)
    first, second = (axis_in_joint(model, joint, tag, x_joint) for tag in ("axis", "axis2"))
    if abs(float(first @ second)) > PERPENDICULAR:
        raise model.source.fail(joint, "a universal joint whose two axes are not perpendicular")
    return first, second


def turned(model, name: str, joint) -> str:
    """The name of the frame the child link takes: the joint frame turned so that x is
    `<axis>` and y `<axis2>` (added to the frame graph)."""
    first, second = axes(model, name, joint)
    frame = f"{name}#universal"  # '#' is no SDF name: no clash
    rot = np.column_stack([first, second, np.cross(first, second)])
    model.frames.add(frame, joint, name, transform(rot, np.zeros(3)))
    return frame


def emit(model, ends: tuple, kit_frame: dict[str, str], line: int | None) -> tuple:
    """The two revolute joints and the link between them (`Joint`s, `Link`); `line`: the
    model's, where the joint has none."""
    name, parent, child, joint = ends
    line = joint.sourceline or line
    frame = kit_frame.get(child)
    if frame != f"{name}#universal":  # a second parent (a loop): left out by the translation
        frame = turned(model, name, joint)
    mid = f"{name}_link"
    parts = ((f"{name}_1", parent, mid, (1.0, 0.0, 0.0), "axis"),
             (name, mid, child, (0.0, 1.0, 0.0), "axis2"))  # fmt: skip
    joints = []
    for k, (joint_name, up, down, xyz, tag) in enumerate(parts):
        if k == 0:
            parent_pose = in_model(model, kit_frame.get(up, up), joint)
            pose = origin(inverse(parent_pose) @ model.frames.in_model(frame, joint), line)
        else:
            pose = origin(np.eye(4), line)
        kind, limit, dynamics = limits(model.source, joint.find(tag), "revolute", line)
        at = At("joint", joint_name, line)
        joints.append(Joint(joint_name, kind, at, up, down, pose, xyz, At("axis", None, line),
                            limit, dynamics))  # fmt: skip
    why = "added: the link between a universal joint's two axes"
    model.source.listed += [(f"links.{mid}", why), (f"joints.{name}_1", why)]
    return joints, Link(mid, At("link", mid, line))
