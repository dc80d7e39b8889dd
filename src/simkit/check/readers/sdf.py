"""An SDFormat model read into a `Tree` (readers/tree.py), by SDFormat 1.9's pose rules.

Defaults as the specification gives them: a link's pose is relative to the model frame, a
joint's to its child link, a frame's to the frame it is attached to (the model frame unless
named); an axis is expressed in the joint frame unless `expressed_in` says otherwise; a link
without <inertial> weighs 1 kg with unit moments (what Gazebo would simulate).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from simkit.check.readers.tree import (
    MODEL,
    WORLD,
    Body,
    Tree,
    TreeJoint,
    body_at,
    floats,
    inertia_matrix,
)
from simkit.model.kinematics import rpy_matrix, transform


def _pose(el: ET.Element | None) -> tuple[np.ndarray, str | None]:
    """(transform, relative_to) of an element's <pose> (identity when absent)."""
    pose = el.find("pose") if el is not None else None
    if pose is None:
        return np.eye(4), None
    values = floats(pose.text, 6)
    return transform(values[:3], rpy_matrix(values[3:])), pose.get("relative_to")


class _Resolver:
    """Zero-configuration poses of the model's links, joints and frames in the model frame."""

    def __init__(self, model: ET.Element) -> None:
        self.raw: dict[str, tuple[np.ndarray, str]] = {}
        for link in model.findall("link"):
            pose, rel = _pose(link)
            self.raw[link.get("name")] = (pose, rel or MODEL)
        for joint in model.findall("joint"):
            pose, rel = _pose(joint)
            self.raw[joint.get("name")] = (pose, rel or joint.findtext("child", "").strip())
        for frame in model.findall("frame"):
            pose, rel = _pose(frame)
            self.raw[frame.get("name")] = (pose, rel or frame.get("attached_to") or MODEL)
        self.done: dict[str, np.ndarray] = {MODEL: np.eye(4), WORLD: np.eye(4)}

    def __call__(self, name: str, seen: frozenset = frozenset()) -> np.ndarray:
        if name in self.done:
            return self.done[name]
        if name not in self.raw or name in seen:
            raise ValueError(f"pose of '{name}': unknown frame or a cycle")
        pose, rel = self.raw[name]
        self.done[name] = self(rel, seen | {name}) @ pose
        return self.done[name]


def read_sdf(path: Path) -> Tree:
    """The file's first model as a tree rooted at its model frame (`__model__`)."""
    sdf = ET.parse(path).getroot()
    model = sdf.find("model")
    if sdf.tag != "sdf" or model is None:
        raise ValueError(f"{path.name}: no <sdf><model>")
    at = _Resolver(model)
    tree = Tree(MODEL)
    for link in model.findall("link"):
        tree.bodies[link.get("name")] = _sdf_body(link.find("inertial"))
        tree.meshes += [(uri.text or "").strip() for uri in link.iter("uri")]
    for joint in model.findall("joint"):
        name, parent = joint.get("name"), joint.findtext("parent", "").strip()
        child = joint.findtext("child", "").strip()
        x_joint = at(name)
        axis_el = joint.find("axis/xyz")
        axis = floats(axis_el.text if axis_el is not None else "0 0 1", 3)
        if axis_el is not None and axis_el.get("expressed_in"):
            rot = np.linalg.inv(x_joint)[:3, :3] @ at(axis_el.get("expressed_in"))[:3, :3]
            axis = rot @ axis
        limits = {
            el.tag: float(el.text)
            for part in ("axis/limit", "axis/dynamics")
            for el in (joint.find(part) if joint.find(part) is not None else [])
        }
        tree.joints.append(
            TreeJoint(
                name,
                joint.get("type"),
                parent,
                child,
                np.linalg.inv(at(parent)) @ x_joint,
                np.linalg.inv(x_joint) @ at(child),
                axis,
                limits,
            )
        )
    moved = {j.child for j in tree.joints}
    tree.placed = {name: at(name) for name in tree.bodies if name not in moved}
    for frame in model.findall("frame"):
        attached = frame.get("attached_to") or MODEL
        tree.frames[frame.get("name")] = (
            attached,
            np.linalg.inv(at(attached)) @ at(frame.get("name")),
        )
    return tree


def _sdf_body(inertial: ET.Element | None) -> Body:
    if inertial is None:
        return Body(1.0, np.zeros(3), np.eye(3))
    i = inertial.find("inertia")
    defaults = {"ixx": 1.0, "ixy": 0.0, "ixz": 0.0, "iyy": 1.0, "iyz": 0.0, "izz": 1.0}
    values = {k: float(i.findtext(k, str(v)) if i is not None else v) for k, v in defaults.items()}
    tensor = inertia_matrix(*(values[k] for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")))
    return body_at(float(inertial.findtext("mass", "1")), _pose(inertial)[0], tensor)
