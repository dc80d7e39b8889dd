"""A compiled MJCF (formats/mjcf/reader.py) to the URDF-shaped tree the shared translation takes.

MuJoCo has compiled the model, so every number here is the simulator's: bodies are links
(inertial from the compiled model: mass, CoM, principal inertia and its axes), hinge ->
revolute (no range: continuous), slide -> prismatic, ball -> a `spherical` joint (three
revolute ones, ball_joints.py), a free root -> the floating base, sites -> frames (massless
leaves on fixed joints), joint actuators -> the joint's effort, geoms -> visuals
(contype = conaffinity = 0) or collisions, meshes as MuJoCo compiled them (scaled, recentred)
written as STL. The shared translation (convert.py) then makes the spec exactly as for a URDF.

Frames: a URDF joint turns about its child link's origin, an MJCF joint about its own `pos`
in the body. A body's link frame is therefore its body frame moved by `offset` (the last
hinge or ball joint's `pos`, body axes; 0 without one); the source check applies the same
rule (check/source/mjcf.py). Several joints in one body become a chain through added
massless links `JOINT_link`. What a kit cannot carry is listed (listed.py).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from simkit.errors import SpecError
from simkit.importer.formats.mjcf import listed as mjcf_listed
from simkit.importer.formats.mjcf import welds
from simkit.importer.formats.mjcf.reader import MjcfSource

#: mjtJoint: free, ball, slide, hinge; mjtGeom
FREE, BALL, SLIDE, HINGE = 0, 1, 2, 3
PLANE, HFIELD, SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH = range(8)


def fmt(values) -> str:
    """Numbers as the shortest text that reads back exactly."""
    return " ".join(repr(float(v)) for v in np.ravel(values))


def rpy(mat: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw (fixed x-y-z, rad) of a rotation matrix."""
    pitch = float(np.arcsin(np.clip(-mat[2, 0], -1.0, 1.0)))
    if abs(mat[2, 0]) < 1.0 - 1e-12:
        return np.array([np.arctan2(mat[2, 1], mat[2, 2]), pitch, np.arctan2(mat[1, 0], mat[0, 0])])
    return np.array([np.arctan2(-mat[1, 2], mat[1, 1]), pitch, 0.0])


def quat_mat(quat) -> np.ndarray:
    """The rotation matrix of a unit quaternion (w, x, y, z), MuJoCo's order."""
    w, x, y, z = (float(v) for v in quat)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def name_of(model, kind: str, index: int) -> str:
    """The element's MJCF name, else KIND + index (MuJoCo allows unnamed elements)."""
    return getattr(model, kind)(index).name or f"{kind}{index}"


def offsets(model) -> np.ndarray:
    """Each body's link frame in its body frame (m, body axes): the last hinge or ball
    joint's `pos`, zero without one (module docstring)."""
    out = np.zeros((model.nbody, 3))
    for j in range(model.njnt):
        if model.jnt_type[j] in (HINGE, BALL):
            out[model.jnt_bodyid[j]] = model.jnt_pos[j]
    return out


def robot_root(model, path: Path, lines: dict | None = None) -> int:
    """The one top-level body carrying joints; one line for none or several (at the
    second robot's body, or the misplaced free joint, where `lines` knows it)."""
    lines = lines or {}
    tops: dict[int, int] = {}
    for j in range(model.njnt):
        top = int(model.body_rootid[model.jnt_bodyid[j]])
        tops[top] = tops.get(top, 0) + 1
    if model.nbody <= 1:
        raise SpecError(str(path), None, "worldbody", "no body: a file to include, not a model")
    if not tops:
        raise SpecError(str(path), None, "worldbody", "no joint: nothing for a kit to move")
    if len(tops) > 1:
        names = ", ".join(name_of(model, "body", b) for b in sorted(tops))
        raise SpecError(
            str(path), lines.get(("body", sorted(tops)[1])), "worldbody",
            f"several robots (top-level bodies with joints: {names}): import one per file",
        )  # fmt: skip
    for j in range(model.njnt):
        body = int(model.jnt_bodyid[j])
        if model.jnt_type[j] == FREE and (body not in tops or model.body_jntnum[body] != 1):
            raise SpecError(
                str(path), lines.get(("jnt", j)), f"joint {name_of(model, 'jnt', j)}",
                "a free joint below the top-level body (or beside other joints): not a robot",
            )  # fmt: skip
    return next(iter(tops))


def to_tree(source: MjcfSource, scratch: Path) -> tuple[object, bool, list[tuple[str, str]]]:
    """The URDF-shaped `<robot>` of the compiled model, meshes written as STL into
    `scratch`; returns (root element, floating, listed differences)."""
    from lxml import etree

    model = source.model
    root_body = robot_root(model, source.path, source.lines)
    off = offsets(model)
    names = Names(model)
    robot = etree.Element("robot", name=model.names[: model.names.find(b"\0")].decode() or "robot")
    bodies = [b for b in range(1, model.nbody) if model.body_rootid[b] == root_body]
    listed = mjcf_listed.collect(model, root_body, bodies)
    added: list[str] = []
    first = int(model.body_jntadr[root_body])
    floating = model.body_jntnum[root_body] > 0 and model.jnt_type[first] == FREE
    moves = model.body_jntnum[root_body] > 0 and not floating  # jointed to the world
    if moves:
        etree.SubElement(robot, "link", name=names.links[0])
    for body in bodies:
        link = _link(robot, model, body, names.links[body], off[body])
        _geoms(link, model, body, off[body], scratch)
        if body != root_body or moves:
            added += _joints(robot, model, body, names, off)
        _sites(robot, model, body, names, off[body])
    why = "added: a link between two joints of one MJCF body"
    listed += [(f"links.{name}", why) for name in added]
    source.closures = welds.closures(model, bodies, names.links)  # loops.close lists them
    carried = {joint.get("listed") for joint in source.closures}
    listed = [(what, reason) for what, reason in listed if what not in carried]
    _lines(robot, source, root_body)
    return robot, bool(floating), listed


def _lines(robot, source: MjcfSource, root_body: int) -> None:
    """Each element's `sourceline`: the MJCF line of the body, joint, geom or site it comes
    from (reader.py `lines`, recorded in the `mjcf` attribute as KIND:ID), else its
    parent element's; the `<robot>` the root body's. The report's records name it, and
    provenance finds an element's records by line and element: so an element without a
    name (a visual, a joint's limit) brought in by an `<include>`, whose line all it brings
    in share, gets none."""
    robot.sourceline = source.lines.get(("body", root_body)) or 0  # 0: none known
    shared = set()
    for element in robot.iter():
        if element is robot:
            continue
        kind, _, index = (element.attrib.pop("mjcf", "") or ":").partition(":")
        key = (kind, int(index)) if index else None
        parent = element.getparent()
        line = source.lines.get(key) if key else None
        if key in source.included or (key is None and parent in shared):
            shared.add(element)
        if line is None and parent not in shared:
            line = parent.sourceline
        if element in shared and element.get("name") is None:
            line = None
        element.sourceline = line or 0


class Names:
    """Link names (bodies, then sites and intermediate links, each unique)."""

    def __init__(self, model) -> None:
        self.links = {b: name_of(model, "body", b) for b in range(model.nbody)}
        self.taken = set(self.links.values()) | {
            name_of(model, "jnt", j) for j in range(model.njnt)
        }

    def new(self, want: str) -> str:
        name, n = want, 1
        while name in self.taken:
            name, n = f"{want}_{n}", n + 1
        self.taken.add(name)
        return name


def _link(robot, model, body: int, name: str, off: np.ndarray) -> object:
    """`<link>` with its inertial (mass kg, CoM m and principal axes in the link frame)."""
    from lxml import etree

    link = etree.SubElement(robot, "link", name=name, mjcf=f"body:{body}")
    if model.body_mass[body] > 0:
        inertial = etree.SubElement(link, "inertial")
        etree.SubElement(
            inertial, "origin", xyz=fmt(model.body_ipos[body] - off),
            rpy=fmt(rpy(quat_mat(model.body_iquat[body]))),
        )  # fmt: skip
        etree.SubElement(inertial, "mass", value=fmt([model.body_mass[body]]))
        ixx, iyy, izz = model.body_inertia[body]
        etree.SubElement(
            inertial, "inertia", ixx=fmt([ixx]), iyy=fmt([iyy]), izz=fmt([izz]),
            ixy="0", ixz="0", iyz="0",
        )  # fmt: skip
    return link


def _origin(parent, xyz, mat) -> None:
    """An `<origin>` (m, URDF rpy rad) under `parent`."""
    from lxml import etree

    etree.SubElement(parent, "origin", xyz=fmt(xyz), rpy=fmt(rpy(mat)))


def _joints(robot, model, body: int, names: Names, off: np.ndarray) -> list[str]:
    """The body's joints as a chain from its parent's link: the first joint's origin is
    the body's pose (less the parent's offset); each later one sits at its own `pos`."""
    from lxml import etree

    parent = int(model.body_parentid[body])
    pose_xyz = model.body_pos[body] - off[parent]
    mat = quat_mat(model.body_quat[body])
    start, added = np.zeros(3), []
    first = int(model.body_jntadr[body])
    count = int(model.body_jntnum[body])
    parent_link = names.links[parent]
    if count == 0:
        joint = etree.SubElement(robot, "joint", name=names.new(f"{names.links[body]}_joint"))
        joint.set("type", "fixed")
        joint.set("mjcf", f"body:{body}")
        _origin(joint, pose_xyz, mat)
        etree.SubElement(joint, "parent", link=parent_link)
        etree.SubElement(joint, "child", link=names.links[body])
        return added
    for k, j in enumerate(range(first, first + count)):
        kind = int(model.jnt_type[j])
        at = model.jnt_pos[j] if kind in (HINGE, BALL) else start
        if k == count - 1:
            child = names.links[body]
        else:
            child = names.new(f"{name_of(model, 'jnt', j)}_link")
            etree.SubElement(robot, "link", name=child, mjcf=f"jnt:{j}")
            added.append(child)
        joint = etree.SubElement(robot, "joint", name=name_of(model, "jnt", j), mjcf=f"jnt:{j}")
        turn, shift = _at_zero(model, j, kind)
        if k == 0:
            _origin(joint, pose_xyz + mat @ (at + shift), mat @ turn)
        else:
            _origin(joint, at - start + shift, turn)
        etree.SubElement(joint, "parent", link=parent_link)
        etree.SubElement(joint, "child", link=child)
        _kind(joint, model, j, kind)
        parent_link, start = child, at
    return added


def _at_zero(model, j: int, kind: int) -> tuple[np.ndarray, np.ndarray]:
    """(rotation, shift m) from the body as written (joint at its `ref`) to the joint at 0:
    MuJoCo turns a joint by q - ref, the kit by q, so both read the same joint values."""
    ref = float(model.qpos0[model.jnt_qposadr[j]]) if kind in (HINGE, SLIDE) else 0.0
    axis = np.asarray(model.jnt_axis[j], dtype=float)
    if kind == SLIDE:
        return np.eye(3), -ref * axis
    x, y, z = axis
    skew = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    turn = np.eye(3) + np.sin(-ref) * skew + (1 - np.cos(-ref)) * skew @ skew
    return turn, np.zeros(3)


def _kind(joint, model, j: int, kind: int) -> None:
    """Type, axis, limits (rad or m; effort N m or N from the joint's actuators) and
    dynamics of one joint."""
    from lxml import etree

    limited = bool(model.jnt_limited[j])
    effort = mjcf_listed.effort(model, j)
    if kind == BALL:
        joint.set("type", "spherical")
        return
    joint.set("type", {HINGE: "revolute" if limited else "continuous", SLIDE: "prismatic"}[kind])
    etree.SubElement(joint, "axis", xyz=fmt(model.jnt_axis[j]))
    limit = {}
    if limited:
        limit = {"lower": fmt([model.jnt_range[j][0]]), "upper": fmt([model.jnt_range[j][1]])}
    if effort is not None:
        limit["effort"] = fmt([effort])
    if limit:
        etree.SubElement(joint, "limit", **limit)
    dof = int(model.jnt_dofadr[j])
    damping, friction = model.dof_damping[dof], model.dof_frictionloss[dof]
    if damping or friction:
        etree.SubElement(joint, "dynamics", damping=fmt([damping]), friction=fmt([friction]))


def _geoms(link, model, body: int, off: np.ndarray, scratch: Path) -> None:
    """Each geom of the body: a `<visual>` when it collides with nothing (contype =
    conaffinity = 0), else a `<collision>`; shapes the URDF form has no word for are listed
    by listed.py."""
    from lxml import etree

    for g in range(
        int(model.body_geomadr[body]), int(model.body_geomadr[body] + model.body_geomnum[body])
    ):
        kind = int(model.geom_type[g])
        if kind not in (SPHERE, CAPSULE, CYLINDER, BOX, MESH) or (
            kind == MESH and mjcf_listed.flat(model, int(model.geom_dataid[g]))
        ):
            continue  # listed (listed.py)
        tag = (
            "visual"
            if model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0
            else "collision"
        )
        element = etree.SubElement(link, tag, mjcf=f"geom:{g}")
        _origin(element, model.geom_pos[g] - off, quat_mat(model.geom_quat[g]))
        geometry = etree.SubElement(element, "geometry")
        size = model.geom_size[g]
        if kind == SPHERE:
            etree.SubElement(geometry, "sphere", radius=fmt([size[0]]))
        elif kind in (CAPSULE, CYLINDER):
            shape = "capsule" if kind == CAPSULE else "cylinder"
            etree.SubElement(geometry, shape, radius=fmt([size[0]]), length=fmt([2 * size[1]]))
        elif kind == BOX:
            etree.SubElement(geometry, "box", size=fmt(2 * size))
        else:
            etree.SubElement(
                geometry, "mesh", filename=str(_stl(model, int(model.geom_dataid[g]), scratch))
            )
        if tag == "visual":
            material = etree.SubElement(element, "material", name=f"mjcf_geom{g}")
            etree.SubElement(material, "color", rgba=fmt(_rgba(model, g)))


def _rgba(model, g: int) -> np.ndarray:
    """The geom's colour: its material's rgba, else its own."""
    mat = int(model.geom_matid[g])
    return model.mat_rgba[mat] if mat >= 0 else model.geom_rgba[g]


def _stl(model, mesh: int, scratch: Path) -> Path:
    """The compiled mesh (MuJoCo's scale and recentring applied, geom frame) as a binary
    STL in `scratch`, written once."""
    names = [re.sub(r"[^A-Za-z0-9_-]+", "_", model.mesh(i).name) for i in range(model.nmesh)]
    name = names[mesh] if names[mesh] and names.count(names[mesh]) == 1 else f"mesh{mesh}"
    path = scratch / f"{name}.stl"
    if path.exists():
        return path
    import trimesh

    start, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    faces_at, faces = int(model.mesh_faceadr[mesh]), int(model.mesh_facenum[mesh])
    vertices = np.asarray(model.mesh_vert[start : start + count], dtype=float)
    triangles = np.asarray(model.mesh_face[faces_at : faces_at + faces])
    trimesh.Trimesh(vertices, triangles, process=False).export(path)
    return path


def _sites(robot, model, body: int, names: Names, off: np.ndarray) -> None:
    """Each named site: a massless leaf link on a fixed joint (a kit frame)."""
    from lxml import etree

    for s in range(model.nsite):
        if model.site_bodyid[s] != body or not model.site(s).name:
            continue
        name = names.new(model.site(s).name)
        joint = etree.SubElement(robot, "joint", name=names.new(f"{name}_joint"), type="fixed")
        joint.set("mjcf", f"site:{s}")
        _origin(joint, model.site_pos[s] - off, quat_mat(model.site_quat[s]))
        etree.SubElement(joint, "parent", link=names.links[body])
        etree.SubElement(joint, "child", link=name)
        etree.SubElement(robot, "link", name=name, mjcf=f"site:{s}")
