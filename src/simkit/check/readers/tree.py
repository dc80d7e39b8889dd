"""URDF and SDFormat files read into one kinematic tree, for comparing them (check/sdf.py).

Pure Python (ElementTree, NumPy): no simulator. A `Tree` holds bodies (mass, kg; centre of
mass, m, and inertia about it, kg m^2, in the body's axes), joints (parent-to-joint and
joint-to-child transforms at zero, the axis in the joint frame) and rigidly attached frames.
`poses(q)` places every body and frame in the file's own root frame (the URDF's root link;
the SDF's model frame, which `world` shares when the model sits at the origin).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simkit.model.kinematics import axis_angle, rpy_matrix, transform

MODEL, WORLD = "__model__", "world"


@dataclass(frozen=True)
class Body:
    mass: float
    com: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True)
class TreeJoint:
    name: str
    type: str
    parent: str
    child: str
    parent_to_joint: np.ndarray
    joint_to_child: np.ndarray
    axis: np.ndarray
    limits: dict[str, float]


@dataclass
class Tree:
    root: str
    bodies: dict[str, Body] = field(default_factory=dict)
    joints: list[TreeJoint] = field(default_factory=list)
    #: name -> (body or frame it is attached to, fixed transform from it)
    frames: dict[str, tuple[str, np.ndarray]] = field(default_factory=dict)
    meshes: list[str] = field(default_factory=list)
    #: bodies no joint moves (an SDF model's free base link): their pose in the root frame
    placed: dict[str, np.ndarray] = field(default_factory=dict)

    def poses(self, q: dict[str, float]) -> dict[str, np.ndarray]:
        """Every body and frame in the root frame, joints at `q` (rad or m; absent: 0)."""
        out = {self.root: np.eye(4), WORLD: np.eye(4), MODEL: np.eye(4), **self.placed}
        pending = list(self.joints)
        while pending:
            ready = [j for j in pending if j.parent in out]
            if not ready:
                raise ValueError(f"joints not connected to the root: {[j.name for j in pending]}")
            for joint in ready:
                motion = _motion(joint, q.get(joint.name, 0.0))
                out[joint.child] = (
                    out[joint.parent] @ joint.parent_to_joint @ motion @ joint.joint_to_child
                )
                pending.remove(joint)
        for name in self.frames:
            out[name] = self._frame(name, out, set())
        return out

    def _frame(self, name: str, out: dict, seen: set) -> np.ndarray:
        if name in out:
            return out[name]
        if name in seen or name not in self.frames:
            raise ValueError(f"frame '{name}' is attached to nothing known")
        seen.add(name)
        attached, fixed = self.frames[name]
        out[name] = self._frame(attached, out, seen) @ fixed
        return out[name]


def _motion(joint: TreeJoint, value: float) -> np.ndarray:
    if joint.type == "prismatic":
        return transform(joint.axis * value)
    if joint.type in ("revolute", "continuous"):
        return transform((0, 0, 0), axis_angle(joint.axis, value))
    return np.eye(4)


def floats(text: str | None, count: int, default: float = 0.0) -> np.ndarray:
    values = [float(v) for v in (text or "").split()]
    if not values:
        return np.full(count, default)
    if len(values) != count:
        raise ValueError(f"expected {count} numbers, got '{text}'")
    return np.array(values)


def inertia_matrix(ixx, ixy, ixz, iyy, iyz, izz) -> np.ndarray:
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]], dtype=float)


def body_at(mass: float, origin: np.ndarray, tensor: np.ndarray) -> Body:
    """Inertia given in a frame at `origin` (centre of mass) turned into link axes."""
    rot = origin[:3, :3]
    return Body(mass, origin[:3, 3].copy(), rot @ tensor @ rot.T)


def read_urdf(path: Path) -> Tree:
    """The URDF's links (a link without <inertial> is massless), joints and mesh files."""
    robot = ET.parse(path).getroot()
    children = {j.find("child").get("link") for j in robot.findall("joint")}
    roots = [link.get("name") for link in robot.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        raise ValueError(f"{path.name}: {len(roots)} root links")
    tree = Tree(roots[0])
    for link in robot.findall("link"):
        inertial = link.find("inertial")
        tree.bodies[link.get("name")] = _urdf_body(inertial)
        tree.meshes += [m.get("filename") for m in link.iter("mesh")]
    for joint in robot.findall("joint"):
        limit = joint.find("limit")
        dynamics = joint.find("dynamics")
        limits = {k: float(v) for el in (limit, dynamics) if el is not None for k, v in el.items()}
        axis = joint.find("axis")
        tree.joints.append(
            TreeJoint(
                joint.get("name"),
                joint.get("type"),
                joint.find("parent").get("link"),
                joint.find("child").get("link"),
                _urdf_origin(joint),
                np.eye(4),
                floats(axis.get("xyz") if axis is not None else "1 0 0", 3),
                limits,
            )
        )
    return tree


def _urdf_origin(el: ET.Element) -> np.ndarray:
    origin = el.find("origin")
    if origin is None:
        return np.eye(4)
    return transform(floats(origin.get("xyz"), 3), rpy_matrix(floats(origin.get("rpy"), 3)))


def _urdf_body(inertial: ET.Element | None) -> Body:
    if inertial is None:
        return Body(0.0, np.zeros(3), np.zeros((3, 3)))
    i = inertial.find("inertia")
    keys = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    tensor = (
        inertia_matrix(*(float(i.get(k, 0.0)) for k in keys)) if i is not None else np.zeros((3, 3))
    )
    mass = inertial.find("mass")
    return body_at(
        float(mass.get("value")) if mass is not None else 0.0, _urdf_origin(inertial), tensor
    )
