"""A compiled MJCF (formats/mjcf/reader.py) to the source model (read/model.py) the shared
translation takes, numbers as floats straight from MuJoCo's arrays (no text between).

MuJoCo has compiled the model, so every number here is the simulator's: bodies are links
(inertial from the compiled model: mass, CoM, principal inertia and its axes), hinge ->
revolute (no range: continuous), slide -> prismatic, ball -> a `spherical` joint (three
revolute ones, translate/ball_joints.py), a free root -> the floating base, sites -> frames
(massless leaves on fixed joints), joint actuators -> the joint's effort, geoms -> visuals
(contype = conaffinity = 0) or collisions, meshes as MuJoCo compiled them (scaled,
recentred) written as STL. The shared translation (translate/convert.py) then makes the
spec exactly as for a URDF. Each node's `At` names the MJCF line it comes from (`Place`).

Frames: a URDF joint turns about its child link's origin, an MJCF joint about its own `pos`
in the body. A body's link frame is therefore its body frame moved by `offset` (the last
hinge or ball joint's `pos`, body axes; 0 without one); the source check applies the same
rule (check/source/mjcf.py). Several joints in one body become a chain through added
massless links `JOINT_link`. What a kit cannot carry is listed (listed.py).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from simkit.errors import SpecError
from simkit.importer.formats.mjcf import listed as mjcf_listed
from simkit.importer.formats.mjcf import welds
from simkit.importer.formats.mjcf.reader import MjcfSource
from simkit.importer.read.model import (
    At,
    Dynamics,
    Geometry,
    Inertial,
    Joint,
    Limit,
    Link,
    Material,
    Pose,
    Robot,
    Shape,
)

#: mjtJoint: free, ball, slide, hinge; mjtGeom
FREE, BALL, SLIDE, HINGE = 0, 1, 2, 3
PLANE, HFIELD, SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH = range(8)


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


def to_robot(source: MjcfSource, scratch: Path) -> tuple[Robot, bool, list[tuple[str, str]]]:
    """The source model of the compiled model's robot, meshes written as STL into
    `scratch`, its body welds in `source.closures`; returns (robot, floating, listed
    differences)."""
    model = source.model
    root_body = robot_root(model, source.path, source.lines)
    off = offsets(model)
    names = Names(model)
    top = Place(source.lines.get(("body", root_body)) or None)
    bodies = [b for b in range(1, model.nbody) if model.body_rootid[b] == root_body]
    listed = mjcf_listed.collect(model, root_body, bodies)
    first = int(model.body_jntadr[root_body])
    floating = model.body_jntnum[root_body] > 0 and model.jnt_type[first] == FREE
    moves = model.body_jntnum[root_body] > 0 and not floating  # jointed to the world
    build = Build(source, model, names, off, top)
    if moves:
        build.links.append(Link(names.links[0], top.inner().at("link", names.links[0])))
    for body in bodies:
        build.body(body, scratch, joints=body != root_body or moves)
    why = "added: a link between two joints of one MJCF body"
    listed += [(f"links.{name}", why) for name in build.added]
    source.closures = welds.closures(model, bodies, names.links)  # loops.close lists them
    carried = {joint.listed for joint in source.closures}
    listed = [(what, reason) for what, reason in listed if what not in carried]
    links, joints = tuple(build.links), tuple(build.joints)
    materials = tuple(g.material for link in links for g in link.visuals if g.material)
    name = model.names[: model.names.find(b"\0")].decode() or "robot"
    return Robot(top.at("robot", name), name, links, joints, materials), bool(floating), listed


@dataclass(frozen=True)
class Place:
    """Where a node is in the MJCF file: its `line` (None: none known) and whether an
    `<include>` brought it in (`shared`: its line is the include's, which all it brings in
    share). A node keeps the line of the body, joint, geom or site it comes from (reader.py
    `lines`), else its parent node's; the robot the root body's. The report's records name
    it, and provenance finds a node's records by line and element: so a node without a name
    (a visual, a joint's limit) brought in by an `<include>` gets none."""

    line: int | None
    shared: bool = False

    def at(self, tag: str, name: str | None = None) -> At:
        """The node's `At`."""
        return At(tag, name, self.line)

    def inner(self) -> Place:
        """The place of a node of no MJCF element of its own (an origin, a limit, a
        material) inside this one."""
        return Place(None if self.shared else self.line, self.shared)

    def of(self, source: MjcfSource, key: tuple[str, int], named: bool) -> Place:
        """The place of the MJCF element `key` (KIND, compiled id) inside this one."""
        shared = key in source.included
        line = source.lines.get(key) or None
        if line is None and not self.shared:
            line = self.line
        return Place(None if shared and not named else line, shared)


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


class Build:
    """The links and joints of the robot's bodies, in the order of the bodies: each body's
    link, the joints that hang it from its parent's (added links between several joints of
    one body), then its sites' joints and links."""

    def __init__(self, source: MjcfSource, model, names: Names, off: np.ndarray, top: Place):
        self.source, self.model, self.names, self.off, self.top = source, model, names, off, top
        self.links: list[Link] = []
        self.joints: list[Joint] = []
        self.added: list[str] = []  # the links between two joints of one body

    def body(self, body: int, scratch: Path, joints: bool) -> None:
        """The body's link (inertial, geoms), its joints when `joints`, its sites."""
        name = self.names.links[body]
        place = self.top.of(self.source, ("body", body), True)
        visuals, collisions = _geoms(self.source, self.model, body, self.off[body], place, scratch)
        inertial = _inertial(self.model, body, self.off[body], place.inner())
        self.links.append(Link(name, place.at("link", name), inertial, visuals, collisions))
        if joints:
            self._joints(body)
        self._sites(body)

    def _joints(self, body: int) -> None:
        """The body's joints as a chain from its parent's link: the first joint's origin is
        the body's pose (less the parent's offset); each later one sits at its own `pos`."""
        model, names = self.model, self.names
        parent = int(model.body_parentid[body])
        pose_xyz = model.body_pos[body] - self.off[parent]
        mat = quat_mat(model.body_quat[body])
        start = np.zeros(3)
        first = int(model.body_jntadr[body])
        count = int(model.body_jntnum[body])
        parent_link = names.links[parent]
        if count == 0:
            name, child = names.new(f"{names.links[body]}_joint"), names.links[body]
            place = self.top.of(self.source, ("body", body), True)
            origin = _pose(pose_xyz, mat, place.inner())
            self.joints.append(
                Joint(name, "fixed", place.at("joint", name), parent_link, child, origin)
            )
            return
        for k, j in enumerate(range(first, first + count)):
            kind = int(model.jnt_type[j])
            at = model.jnt_pos[j] if kind in (HINGE, BALL) else start
            place = self.top.of(self.source, ("jnt", j), True)
            if k == count - 1:
                child = names.links[body]
            else:
                child = names.new(f"{name_of(model, 'jnt', j)}_link")
                self.links.append(Link(child, place.at("link", child)))
                self.added.append(child)
            turn, shift = _at_zero(model, j, kind)
            if k == 0:
                origin = _pose(pose_xyz + mat @ (at + shift), mat @ turn, place.inner())
            else:
                origin = _pose(at - start + shift, turn, place.inner())
            name = name_of(model, "jnt", j)
            joint = Joint(name, "fixed", place.at("joint", name), parent_link, child, origin)
            self.joints.append(_kind(joint, model, j, kind, place.inner()))
            parent_link, start = child, at

    def _sites(self, body: int) -> None:
        """Each named site: a massless leaf link on a fixed joint (a kit frame)."""
        model, names, off = self.model, self.names, self.off[body]
        for s in range(model.nsite):
            if model.site_bodyid[s] != body or not model.site(s).name:
                continue
            name = names.new(model.site(s).name)
            joint = names.new(f"{name}_joint")
            place = self.top.of(self.source, ("site", s), True)
            origin = _pose(model.site_pos[s] - off, quat_mat(model.site_quat[s]), place.inner())
            self.joints.append(
                Joint(joint, "fixed", place.at("joint", joint), names.links[body], name, origin)
            )
            self.links.append(Link(name, place.at("link", name)))


def floats(values) -> tuple[float, ...]:
    """The numbers as plain floats (the model is typed: no numpy scalars)."""
    return tuple(float(v) for v in np.ravel(values))


def _pose(xyz, mat: np.ndarray, place: Place) -> Pose:
    """An origin (m, URDF rpy rad) at `place`."""
    return Pose(floats(xyz), floats(rpy(mat)), place.at("origin"))  # type: ignore[arg-type]


def _inertial(model, body: int, off: np.ndarray, place: Place) -> Inertial | None:
    """The body's inertial (mass kg, CoM m and principal axes in the link frame; inertia
    kg m^2 about them), None when massless."""
    if not model.body_mass[body] > 0:
        return None
    ixx, iyy, izz = floats(model.body_inertia[body])
    return Inertial(
        place.at("inertial"),
        _pose(model.body_ipos[body] - off, quat_mat(model.body_iquat[body]), place),
        float(model.body_mass[body]),
        place.at("mass"),
        (ixx, iyy, izz, 0.0, 0.0, 0.0),
        place.at("inertia"),
    )


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


def _kind(joint: Joint, model, j: int, kind: int, place: Place) -> Joint:
    """Type, axis, limits (rad or m; effort N m or N from the joint's actuators) and
    dynamics of one joint."""
    if kind == BALL:
        return replace(joint, type="spherical")
    limited = bool(model.jnt_limited[j])
    effort = mjcf_listed.effort(model, j)
    kinds = {HINGE: "revolute" if limited else "continuous", SLIDE: "prismatic"}
    lower, upper = floats(model.jnt_range[j]) if limited else (None, None)
    limit = None
    if limited or effort is not None:
        limit = Limit(place.at("limit"), lower, upper, None if effort is None else float(effort))
    dof = int(model.jnt_dofadr[j])
    damping, friction = float(model.dof_damping[dof]), float(model.dof_frictionloss[dof])
    dynamics = Dynamics(place.at("dynamics"), damping, friction) if damping or friction else None
    return replace(
        joint, type=kinds[kind], axis=floats(model.jnt_axis[j]), axis_at=place.at("axis"),
        limit=limit, dynamics=dynamics,
    )  # fmt: skip


def _geoms(source: MjcfSource, model, body: int, off: np.ndarray, link: Place, scratch: Path):
    """Each geom of the body: a visual when it collides with nothing (contype =
    conaffinity = 0), else a collision; returns (visuals, collisions). Shapes the URDF
    form has no word for are listed by listed.py."""
    visuals: list[Geometry] = []
    collisions: list[Geometry] = []
    for g in range(
        int(model.body_geomadr[body]), int(model.body_geomadr[body] + model.body_geomnum[body])
    ):
        kind = int(model.geom_type[g])
        if kind not in (SPHERE, CAPSULE, CYLINDER, BOX, MESH) or (
            kind == MESH and mjcf_listed.flat(model, int(model.geom_dataid[g]))
        ):
            continue  # listed (listed.py)
        visual = model.geom_contype[g] == 0 and model.geom_conaffinity[g] == 0
        tag = "visual" if visual else "collision"
        place = link.of(source, ("geom", g), False)
        inner = place.inner()
        origin = _pose(model.geom_pos[g] - off, quat_mat(model.geom_quat[g]), inner)
        shape = _shape(model, g, kind, inner, scratch)
        material = None
        if visual:
            rgba = floats(_rgba(model, g))
            material = Material(inner.at("material", f"mjcf_geom{g}"), f"mjcf_geom{g}", rgba)  # type: ignore[arg-type]
        geometry = Geometry(place.at(tag), origin, shape, material)
        (visuals if visual else collisions).append(geometry)
    return tuple(visuals), tuple(collisions)


def _shape(model, g: int, kind: int, place: Place, scratch: Path) -> Shape:
    """The geom's shape (sizes m), a mesh written as STL into `scratch`."""
    size = model.geom_size[g]
    if kind == SPHERE:
        return Shape("sphere", place.at("sphere"), radius=float(size[0]))
    if kind in (CAPSULE, CYLINDER):
        tag = "capsule" if kind == CAPSULE else "cylinder"
        return Shape(tag, place.at(tag), radius=float(size[0]), length=float(2 * size[1]))
    if kind == BOX:
        return Shape("box", place.at("box"), size=floats(2 * size))  # type: ignore[arg-type]
    filename = str(_stl(model, int(model.geom_dataid[g]), scratch))
    return Shape("mesh", place.at("mesh"), filename=filename)


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
