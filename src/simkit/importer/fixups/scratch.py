"""One builder for the scratch MuJoCo models the import's searches measure a robot on.

The pose searches (home.py, gravity.py, limits.py, stance.py) and the settle (settle.py)
each compile a small MJCF of the resolved robot that no kit ever holds: collision geometry
only, or with the real masses and servos. `Scratch` writes its sections in MuJoCo's order
(compiler, option, default, asset, worldbody, contact, then any other) and its bodies, joints
and geoms from the model's links and joints; `compiled` returns the model, its data and the
qpos address of each joint. Lengths in m, angles in rad, masses in kg, poses in the link's
parent frame (spec order). It imports only model/ and kitio/, so it can move to model/ for
derive/collision_pairs.py to share (docs/architecture.md).
"""

from __future__ import annotations

import hashlib
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from simkit.kitio import interrupt
from simkit.kitio.stl import from_stl
from simkit.model.kinematics import quat_wxyz, rpy_matrix

#: MJCF joint type of each movable spec joint type (fixed and floating joints have none)
KINDS = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide"}


def text(values) -> str:
    """Numbers as MJCF text, full precision (repr)."""
    return " ".join(repr(float(v)) for v in np.ravel(values))


#: a mesh's vertex text by (STL digest, scale): an import compiles a dozen scratch models of
#: the same meshes, and reading, merging and printing a CAD mesh's vertices cost more than
#: MuJoCo's compile of them; the bytes are the same either way
_VERTEX_TEXT: dict[tuple[bytes, tuple[float, ...]], str] = {}
_VERTEX_TEXT_MAX = 1024


def mesh_text(path: Path, scale) -> str:
    """The MJCF `vertex` text of the STL at `path` (merged vertices, scaled), computed once
    per file content and scale."""
    data = path.read_bytes()
    key = (hashlib.sha256(data).digest(), tuple(float(v) for v in np.ravel(scale)))
    found = _VERTEX_TEXT.get(key)
    if found is None:
        if len(_VERTEX_TEXT) >= _VERTEX_TEXT_MAX:
            _VERTEX_TEXT.clear()
        found = _VERTEX_TEXT[key] = text(from_stl(data).vertices * scale)
    return found


def principal(tensor) -> dict[str, str]:
    """MJCF `diaginertia` and `quat` of an inertia tensor (kg m^2, link axes): its principal
    moments, none below a speck (an inertia_decision may keep one that is not positive
    definite, a quadruped's base)."""
    from scipy.spatial.transform import Rotation

    moments, axes = np.linalg.eigh(np.asarray(tensor, dtype=float))
    if np.linalg.det(axes) < 0:
        axes[:, 0] = -axes[:, 0]
    moments = np.maximum(moments, 1e-12)  # the compiler balances a + b < c (balanceinertia)
    x, y, z, w = Rotation.from_matrix(axes).as_quat()
    return {"diaginertia": text(moments), "quat": text([w, x, y, z])}


class Scratch:
    """An MJCF under construction: `compiler`, `option` (with its `flag`s) and the `geom`
    defaults as attribute dicts; the asset and worldbody sections are open to add to."""

    def __init__(
        self,
        compiler: dict[str, str],
        geom: dict[str, str],
        option: dict[str, str] | None = None,
        flags: dict[str, str] | None = None,
    ) -> None:
        self.root = ET.Element("mujoco")
        ET.SubElement(self.root, "compiler", compiler)
        if option is not None or flags is not None:
            element = ET.SubElement(self.root, "option", option or {})
            if flags is not None:
                ET.SubElement(element, "flag", flags)
        ET.SubElement(ET.SubElement(self.root, "default"), "geom", geom)
        self.asset = ET.SubElement(self.root, "asset")
        self.world = ET.SubElement(self.root, "worldbody")

    def body(self, parent: ET.Element, name: str, xyz, rpy) -> ET.Element:
        """A body `name` under `parent` at `xyz` (m) and `rpy` (rad) in its frame."""
        quat = text(quat_wxyz(rpy_matrix(rpy)))
        return ET.SubElement(parent, "body", name=name, pos=text(xyz), quat=quat)

    def unit_inertial(self, body: ET.Element) -> None:
        """A unit mass and inertia: the searches measure contact, not dynamics."""
        ET.SubElement(body, "inertial", pos="0 0 0", mass="1", diaginertia="1 1 1")

    def inertial(self, body: ET.Element, link) -> None:
        """The link's real inertial; a massless link a speck, so MuJoCo moves its body."""
        inertial = link.inertial
        if inertial is not None and inertial.mass > 0:
            ET.SubElement(
                body,
                "inertial",
                pos=text(inertial.com),
                mass=repr(float(inertial.mass)),
                **principal(inertial.tensor()),
            )
        else:
            ET.SubElement(body, "inertial", pos="0 0 0", mass="1e-6", diaginertia="1e-9 1e-9 1e-9")

    def joint(self, body: ET.Element, joint, **extra: str) -> None:
        """The hinge or slide of a movable spec joint (`extra`: more MJCF attributes)."""
        kind = KINDS.get(joint.type)
        if kind:
            ET.SubElement(body, "joint", name=joint.name, type=kind, axis=text(joint.axis), **extra)

    def geoms(self, body: ET.Element, link, shapes, base_dir: Path) -> None:
        """A geom per shape, named `LINK_i`; a mesh's vertices (its hull, to MuJoCo) read
        from `base_dir` and scaled."""
        for i, shape in enumerate(shapes):
            self.geom(body, shape, base_dir, f"{link.name}_{i}")

    def geom(self, body: ET.Element, shape, base_dir: Path, name: str) -> None:
        """One geom of a spec shape in the link frame (a cone: its bounding cylinder)."""
        attrs = {"pos": text(shape.xyz), "quat": text(quat_wxyz(rpy_matrix(shape.rpy)))}
        if shape.kind == "mesh":
            vertex = mesh_text(base_dir / shape.file, shape.scale)
            ET.SubElement(self.asset, "mesh", name=name, vertex=vertex)
            attrs.update(type="mesh", mesh=name)
        elif shape.kind == "box":
            attrs.update(type="box", size=text(np.asarray(shape.size) / 2))
        elif shape.kind == "sphere":
            attrs.update(type="sphere", size=text([shape.radius]))
        elif shape.kind in ("cylinder", "capsule"):
            attrs.update(type=shape.kind, size=text([shape.radius, shape.length / 2]))
        else:
            radius = max(shape.radius, shape.radius_top or 0)
            attrs.update(type="cylinder", size=text([radius, shape.length / 2]))
        ET.SubElement(body, "geom", attrs)

    def tree(self, robot, base_dir: Path, shapes_of) -> None:
        """The robot's body tree under the worldbody (the root link is the world), unit
        masses, hinge or slide joints, a geom per shape `shapes_of(link)` gives: the
        collision-only model of the contact searches."""
        bodies = {robot.root: self.world}
        for joint in robot.joints:
            link = robot.link(joint.child)
            body = self.body(bodies[joint.parent], link.name, joint.xyz, joint.rpy)
            bodies[link.name] = body
            self.unit_inertial(body)
            self.joint(body, joint)
            self.geoms(body, link, shapes_of(link), base_dir)

    def section(self, tag: str) -> ET.Element:
        """A new top-level section (`equality`, `actuator`) after those written so far."""
        return ET.SubElement(self.root, tag)

    def exclude(self, pairs) -> None:
        """The contact section: each (body, body) pair of `pairs`, in order, never collides."""
        contact = self.section("contact")
        for a, b in pairs:
            ET.SubElement(contact, "exclude", body1=a, body2=b)

    def xml(self) -> str:
        return ET.tostring(self.root, encoding="unicode")


#: compiled scratch models by their MJCF's digest: the searches of one import compile the
#: same collision model several times (the home search, the always-touching pairs, the
#: limits); no caller changes a model, each gets its own data
_COMPILED: dict[bytes, object] = {}
_COMPILED_MAX = 8


def compiled(xml: str, joints) -> tuple:
    """(model, data, qpos address of each of `joints`) of a scratch MJCF, compiled once per
    text (a fresh MjData each call). MuJoCo is imported in a held section
    (kitio/interrupt.py): a signal that arrives while its extension initialises would break
    that import (an ImportError, not the clean interruption), so it takes effect once the
    import is done."""
    with interrupt.held():
        import mujoco

    key = hashlib.sha256(xml.encode()).digest()
    model = _COMPILED.get(key)
    if model is None:
        if len(_COMPILED) >= _COMPILED_MAX:
            _COMPILED.clear()
        model = _COMPILED[key] = mujoco.MjModel.from_xml_string(xml)
    adr = np.array([model.jnt_qposadr[model.joint(j.name).id] for j in joints], dtype=int)
    return model, mujoco.MjData(model), adr
