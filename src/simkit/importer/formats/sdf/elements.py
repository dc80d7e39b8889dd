"""The URDF-shaped elements written for an SDF model's joints and frames (tree.py and
universal.py share them): a frame's pose in the model frame, an `<origin>`, an axis in its
joint frame (`expressed_in`), and `<limit>`/`<dynamics>`. Numbers are written exactly
(`repr`), so the shared translation reads back the reader's values."""

from __future__ import annotations

import numpy as np

from simkit.importer.formats.sdf.frames import MODEL, WORLD, inverse, numbers, rpy_of, scoped

#: |limit| at or above which an SDF limit means none (the specification's default is 1e16)
NO_LIMIT = 1e15


def fmt(values) -> str:
    """Numbers as a URDF attribute: exact (repr), space-separated."""
    return " ".join(repr(float(v)) for v in np.ravel(values))


def in_model(model, name: str, element) -> np.ndarray:
    """A frame's pose in the top model frame (the world: the model's pose inverted)."""
    if name == WORLD:
        return inverse(model.source.placed)
    return model.frames.in_model(name, element)


def origin(parent, x: np.ndarray) -> None:
    from lxml import etree

    etree.SubElement(parent, "origin", xyz=fmt(x[:3, 3]), rpy=fmt(rpy_of(x[:3, :3])))


def axis_in_joint(model, joint, tag: str, x_joint: np.ndarray) -> np.ndarray:
    """The unit axis of `<axis>` (or `<axis2>`) in the joint frame: its `<xyz>` expressed in
    the joint frame unless `expressed_in` (or 1.4-1.6 `use_parent_model_frame`) says."""
    src = model.source
    axis = joint.find(tag)
    xyz = axis.find("xyz") if axis is not None else None
    if xyz is None:
        raise src.fail(joint, f"a {joint.get('type')} joint without <{tag}><xyz>")
    vector = np.asarray(numbers(src, xyz, xyz.text, 3))
    if not np.linalg.norm(vector):
        raise src.fail(xyz, "a zero axis")
    frame = xyz.get("expressed_in")
    if not frame and (axis.findtext("use_parent_model_frame") or "").strip() in ("true", "1"):
        frame = MODEL
    if frame:
        rot = x_joint[:3, :3].T @ in_model(model, scoped(xyz.get("scope", ""), frame), xyz)[:3, :3]
        vector = rot @ vector
    return vector / np.linalg.norm(vector)


def limits(out, src, axis, kind: str) -> None:
    from lxml import etree

    limit = axis.find("limit")

    def value(tag: str) -> float | None:
        found = None if limit is None else limit.find(tag)
        return None if found is None else numbers(src, found, found.text, 1)[0]

    lower, upper, effort, velocity = (value(t) for t in ("lower", "upper", "effort", "velocity"))
    bounded = lower is not None and upper is not None and max(abs(lower), abs(upper)) < NO_LIMIT
    if kind == "revolute" and not bounded:
        out.set("type", "continuous")
    attrs = {"lower": fmt([lower]), "upper": fmt([upper])} if bounded else {}
    if effort is not None and effort > 0:
        attrs["effort"] = fmt([effort])
    if velocity is not None and velocity > 0:
        attrs["velocity"] = fmt([velocity])
    if attrs:
        etree.SubElement(out, "limit", **attrs)
    damping = axis.findtext("dynamics/damping")
    friction = axis.findtext("dynamics/friction")
    if damping or friction:
        etree.SubElement(
            out,
            "dynamics",
            damping=fmt([float(damping or 0)]),
            friction=fmt([float(friction or 0)]),
        )
