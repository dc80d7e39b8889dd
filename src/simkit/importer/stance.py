"""A home pose free of self-contact for a floating-base import, feet left where they are.

The importer's first guess at `home` is 0 for every joint (mid-range where 0 is outside).
Humanoids often hang their arms through their thighs at 0 (Talos's grippers sit 7 cm inside
its thigh hulls), so the kit's servos would hold a pose its own links penetrate and the
robot pushes itself over. This module measures self-contact with MuJoCo on the links'
collision geometry as the spec gives it (primitives, the convex hull of each given collision
mesh, else of each visual piece) with the kit's exclusions (links joined by a joint or welded
by fixed joints), ignores pairs in contact in every sampled configuration (the kit excludes
those, derive/collision_pairs.always_pairs), and moves one joint at a time to the value on a
grid of its range that leaves the least penetration. Joints that carry a foot (a link whose
lowest point at home is on the floor) stay put: the stance is the standing check's business.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

GRID = 8  # range divisions tried per joint
SWEEPS = 2
SAMPLES = 200  # random configurations that tell an always-touching pair
FOOT = 0.01  # m: a link whose lowest point is this close to the robot's lowest is a foot


def _text(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def _shapes(link) -> tuple:
    return link.collision_primitives or link.collision_shapes or link.shapes


def _geom(asset, body, shape, base_dir: Path, name: str) -> None:
    from simkit.kitio.stl import from_stl
    from simkit.model.kinematics import quat_wxyz, rpy_matrix

    attrs = {"pos": _text(shape.xyz), "quat": _text(quat_wxyz(rpy_matrix(shape.rpy)))}
    if shape.kind == "mesh":
        vertices = from_stl((base_dir / shape.file).read_bytes()).vertices * shape.scale
        ET.SubElement(asset, "mesh", name=name, vertex=_text(vertices))
        attrs.update(type="mesh", mesh=name)
    elif shape.kind == "box":
        attrs.update(type="box", size=_text(np.asarray(shape.size) / 2))
    elif shape.kind == "sphere":
        attrs.update(type="sphere", size=_text([shape.radius]))
    else:  # cylinder, capsule; a cone as its bounding cylinder
        radius = max(shape.radius, getattr(shape, "radius_top", None) or 0.0)
        kind = "capsule" if shape.kind == "capsule" else "cylinder"
        attrs.update(type=kind, size=_text([radius, shape.length / 2]))
    ET.SubElement(body, "geom", attrs)


def _model_xml(robot, base_dir: Path) -> str:
    """Collision geometry only; every body but a fixed joint's child moves (fixed children
    are welded, as MuJoCo does in the kit), the parent filter on."""
    from simkit.model.kinematics import quat_wxyz, rpy_matrix

    root = ET.Element("mujoco")
    ET.SubElement(root, "compiler", angle="radian")
    ET.SubElement(ET.SubElement(root, "default"), "geom", contype="1", conaffinity="1")
    asset = ET.SubElement(root, "asset")
    bodies = {robot.root: ET.SubElement(root, "worldbody")}
    for joint in robot.joints:
        link = robot.link(joint.child)
        quat = _text(quat_wxyz(rpy_matrix(joint.rpy)))
        body = ET.SubElement(
            bodies[joint.parent], "body", name=link.name, pos=_text(joint.xyz), quat=quat
        )
        bodies[link.name] = body
        ET.SubElement(body, "inertial", pos="0 0 0", mass="1", diaginertia="1 1 1")
        kind = {"revolute": "hinge", "continuous": "hinge", "prismatic": "slide"}.get(joint.type)
        if kind:
            ET.SubElement(body, "joint", name=joint.name, type=kind, axis=_text(joint.axis))
        for i, shape in enumerate(_shapes(link)):
            _geom(asset, body, shape, base_dir, f"{link.name}_{i}")
    contact = ET.SubElement(root, "contact")
    links = {link.name for link in robot.links}
    for joint in robot.joints:
        if joint.parent in links:
            ET.SubElement(contact, "exclude", body1=joint.parent, body2=joint.child)
    return ET.tostring(root, encoding="unicode")


def _contacts(model, data, adr, q) -> dict[tuple[str, str], float]:
    """Deepest penetration (m, > 0) per touching body pair at `q`."""
    import mujoco

    data.qpos[adr] = q
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    out: dict[tuple[str, str], float] = {}
    for contact in data.contact[: data.ncon]:
        a = model.body(model.geom_bodyid[contact.geom1]).name
        b = model.body(model.geom_bodyid[contact.geom2]).name
        pair = (a, b) if a < b else (b, a)
        out[pair] = max(out.get(pair, 0.0), -float(contact.dist))
    return out


def _feet_joints(robot, home, base_dir: Path) -> set[str]:
    """Joints on the way from the base to any link whose lowest point at home is a foot."""
    from simkit.importer.standing import _points
    from simkit.model.kinematics import forward

    poses = forward(robot, home)
    low: dict[str, float] = {}
    for link in robot.links:
        for shape in link.shapes:
            world = _points(shape, base_dir) @ poses[link.name][:3, :3].T
            z = float((world[:, 2] + poses[link.name][2, 3]).min())
            low[link.name] = min(low.get(link.name, math.inf), z)
    if not low:
        return set()
    lowest = min(low.values())
    parent = {j.child: j for j in robot.joints}
    out: set[str] = set()
    for name, z in low.items():
        while z <= lowest + FOOT and name in parent:
            out.add(parent[name].name)
            name = parent[name].parent
    return out


def free_home(spec_path: Path) -> tuple[list[float], list[str]] | None:
    """A home pose (spec order) whose separable link pairs do not touch, and the changes
    made (`joint: a -> b`); None when home is already free or no grid pose frees it."""
    import mujoco
    import yaml

    from simkit.model.resolve import resolve
    from simkit.spec.schema import RobotSpec

    text = spec_path.read_text(encoding="utf-8")
    robot = resolve(RobotSpec.model_validate(yaml.safe_load(text)), text.encode(), spec_path.name)
    home = dict(robot.poses).get("home")
    if home is None:
        return None
    model = mujoco.MjModel.from_xml_string(_model_xml(robot, spec_path.parent))
    data = mujoco.MjData(model)
    movable = robot.movable_joints
    adr = np.array([model.jnt_qposadr[model.joint(j.name).id] for j in movable], dtype=int)
    limits = [(j.lower, j.upper) if j.lower is not None else (-math.pi, math.pi) for j in movable]
    unit = np.random.default_rng(0).random((SAMPLES, len(movable)))
    always: set | None = None
    for u in unit:
        q = np.array([lo + x * (hi - lo) for x, (lo, hi) in zip(u, limits, strict=True)])
        touching = set(_contacts(model, data, adr, q))
        always = touching if always is None else always & touching
    always = always or set()

    def depth(q) -> float:
        return sum(d for p, d in _contacts(model, data, adr, q).items() if p not in always)

    start = np.array(home, dtype=float)
    q, best = start.copy(), depth(start)
    if best == 0.0:
        return None
    frozen = _feet_joints(robot, home, spec_path.parent)
    index = {j.name: i for i, j in enumerate(movable)}
    for _ in range(SWEEPS):
        for j, (lo, hi) in reversed(list(zip(movable, limits, strict=True))):
            if j.name in frozen or j.mimic is not None:
                continue
            i = index[j.name]
            grid = np.linspace(lo, hi, GRID + 1)[1:-1]  # not at a limit, where a servo rests
            for value in sorted(grid, key=lambda v: abs(v - start[i])):
                trial = q.copy()
                trial[i] = value
                for m in movable:  # mimic joints follow their leaders
                    if m.mimic is not None and m.mimic[0] in index:
                        trial[index[m.name]] = m.mimic[1] * trial[index[m.mimic[0]]] + m.mimic[2]
                got = depth(trial)
                if got < best - 1e-9:
                    q, best = trial, got
            if best == 0.0:
                break
        if best == 0.0:
            break
    if best > 0.0:
        return None
    changes = [
        f"{j.name}: {start[i]:.4g} -> {q[i]:.4g}"
        for i, j in enumerate(movable)
        if abs(q[i] - start[i]) > 1e-12
    ]
    return [float(f"{v:.6g}") for v in q], changes
