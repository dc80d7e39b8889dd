"""The GPU scene's colliders (derive/gpu_scene.py) and a scratch MuJoCo model of them, for
sampling which collider pairs touch and where the robot stands. Colliders are plain dicts
(`products.gpu_scene["colliders"]`): link, name, kind, placement in the link frame (m, rad)
and size (m)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from simkit.derive.collision import MAX_PIECES
from simkit.derive.collision_pairs import (
    follow_mimics,
    sampled_joints,
    scratch_body,
    welded_pairs,
)
from simkit.derive.solids import is_convex_union
from simkit.model.kinematics import excluded_pairs, jointed_pairs, quat_wxyz, rpy_matrix
from simkit.model.robot import Link, Robot, Shape

#: MJX's guidance: fewer than 32 vertices for convex-convex collisions
MAX_HULL_VERTICES = 24
TOUCH = 1e-6  # m: margin of the sampled contacts (faces that meet exactly count)


def mujoco_type(kind: str) -> str:
    """The MuJoCo geom type of a collider kind (pieces are meshes)."""
    return "mesh" if kind == "piece" else kind


def _primitive(link: Link, shape: Shape, name: str) -> dict:
    out = {"link": link.name, "name": name, "kind": shape.kind, "class": shape.geom_class}
    out["xyz"], out["rpy"] = [float(v) for v in shape.xyz], [float(v) for v in shape.rpy]
    if shape.kind == "box":
        out["size"] = [float(v) for v in shape.size]  # full edge lengths (m)
    else:
        out["radius"] = float(shape.radius)
        if shape.kind in ("capsule", "cylinder", "cone"):
            out["length"] = float(shape.length)
        if shape.kind == "cone":
            out["radius_top"] = float(shape.radius_top)
    return out


def colliders(link: Link) -> list[dict]:
    """The link's GPU colliders (names as the main MJCF's collision geoms)."""
    if link.collision_primitives:
        single = len(link.collision_primitives) == 1
        return [
            _primitive(link, s, f"{link.name}_collision" + ("" if single else f"_{i:02d}"))
            for i, s in enumerate(link.collision_primitives)
        ]
    if link.collision_method == "primitives":
        return []
    shapes = link.shapes
    if is_convex_union(shapes) and len(shapes) <= MAX_PIECES and len(link.collision) == len(shapes):
        out = [_primitive(link, s, f"{link.name}_collision_{i:02d}") for i, s in enumerate(shapes)]
        for geom in out:
            if geom["kind"] == "cone":  # the smallest cylinder that covers it
                geom["kind"] = "cylinder"
                geom["radius"] = max(geom["radius"], geom.pop("radius_top"))
        return out
    pieces = link.collision or ((link.solid,) if link.solid is not None else ())
    return [
        {"link": link.name, "name": f"{link.name}_collision_{i:02d}", "kind": "piece", "piece": i}
        for i in range(len(pieces))
    ]


def piece_vertices(robot: Robot, geom: dict) -> np.ndarray:
    """A piece's vertices (link frame, m): the kit's collision piece, or the visual solid."""
    link = robot.link(geom["link"])
    pieces = link.collision or (link.solid,)
    return np.asarray(pieces[geom["piece"]].vertices)


# --- the scratch model: colliders on the robot's bodies, for sampling and the stance ------


def _text(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def scratch_geom(
    robot: Robot, asset: ET.Element, body: ET.Element, geom: dict, own_cap: bool = False
) -> None:
    """A collider in a scratch model; a piece's hull capped at `MAX_HULL_VERTICES`, or with
    `own_cap` at the plan's `maxhullvert` (as the GPU scene writes it)."""
    attrs = {"name": geom["name"]}
    kind = geom["kind"]
    if kind == "piece":
        vertices = piece_vertices(robot, geom)
        mesh = {"name": geom["name"], "vertex": _text(vertices)}
        cap = geom.get("maxhullvert") if own_cap else MAX_HULL_VERTICES
        if cap is not None and len(vertices) > cap:
            mesh["maxhullvert"] = str(cap)
        ET.SubElement(asset, "mesh", mesh)
        attrs.update(type="mesh", mesh=geom["name"])
    else:
        attrs.update(pos=_text(geom["xyz"]), quat=_text(quat_wxyz(rpy_matrix(geom["rpy"]))))
        if kind == "box":
            attrs.update(type="box", size=_text(np.asarray(geom["size"]) / 2))
        elif kind == "sphere":
            attrs.update(type="sphere", size=_text([geom["radius"]]))
        else:  # capsule, cylinder: radius and half-length along local z
            attrs.update(type=kind, size=_text([geom["radius"], geom["length"] / 2]))
    ET.SubElement(body, "geom", attrs)


def scratch_xml(
    robot: Robot, geoms: list[dict], skip: set[tuple[str, str]], floor: float | None = None
) -> str:
    """MJCF of the colliders on the robot's bodies at their joint origins (a floating base at
    its spec origin, locked), every link pair but `skip` colliding, the parent filter off;
    with `floor` (m), also a plane `floor` at the root's z = 0 with that contact margin."""
    root = ET.Element("mujoco", model=f"{robot.name}_gpu_pairs")
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false")
    ET.SubElement(ET.SubElement(root, "option"), "flag", filterparent="disable", gravity="disable")
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", contype="1", conaffinity="1", margin=repr(TOUCH / 2))
    asset = ET.SubElement(root, "asset")
    bodies = {robot.root: ET.SubElement(root, "worldbody")}
    if floor is not None:
        plane = {"name": "floor", "type": "plane", "size": "0 0 1", "margin": repr(floor)}
        ET.SubElement(bodies[robot.root], "geom", plane)
    by_link: dict[str, list[dict]] = {}
    for geom in geoms:
        by_link.setdefault(geom["link"], []).append(geom)
    for joint in robot.joints:
        body = bodies[joint.child] = scratch_body(bodies[joint.parent], joint)
        for geom in by_link.get(joint.child, []):
            scratch_geom(robot, asset, body, geom)
    contact = ET.SubElement(root, "contact")
    for a, b in sorted(skip):
        ET.SubElement(contact, "exclude", body1=a, body2=b)
    return ET.tostring(root, encoding="unicode")


def never_collided(robot: Robot) -> set[tuple[str, str]]:
    """Link pairs the main MJCF never collides: joined by a joint, welded (MuJoCo's own
    filters) and the `always` and declared pairs it excludes; sorted name pairs."""
    pairs = {tuple(sorted(p)) for p in jointed_pairs(robot)} | welded_pairs(robot)
    return pairs | {tuple(sorted(p)) for p in excluded_pairs(robot)}


def sampled_contacts(robot: Robot, geoms: list[dict], q: np.ndarray) -> list[tuple[float, set]]:
    """For each configuration of `q` with a contact: the deepest penetration (m) and the
    collider pairs in contact (within `TOUCH`), as sorted name pairs."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(scratch_xml(robot, geoms, never_collided(robot)))
    data = mujoco.MjData(model)
    names = [j for j, _, _ in sampled_joints(robot)]
    adr = np.array([model.jnt_qposadr[model.joint(n).id] for n in names], dtype=int)
    geom_name = [model.geom(i).name for i in range(model.ngeom)]
    out: list[tuple[float, set]] = []
    for row in follow_mimics(robot, q) if len(names) else []:
        data.qpos[adr] = row
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        if data.ncon:
            geom = data.contact.geom[: data.ncon]
            depth = float(max(0.0, -data.contact.dist[: data.ncon].min()))
            out.append((depth, {tuple(sorted((geom_name[a], geom_name[b]))) for a, b in geom}))
    return out
