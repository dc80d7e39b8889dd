"""A USD articulation (stage.py) to the source model the shared translation takes
(read/model.py `Robot`: links and joints in URDF terms, numbers as the floats computed here,
no text; a stage has no lines, so every node's place has none).

Frames: a UsdPhysics joint joins body0's frame `localPos0/localRot0` to body1's
`localPos1/localRot1`, and turns about its `axis` (X, Y or Z) of that joint frame. A URDF
joint turns about its child link's origin, so a link's frame is its body's frame moved (not
turned) to the joint frame on it (`localPos1` of the joint it hangs from; the root's own body
frame, or its world joint's `localPos1`); the joint's axis is `localRot1` applied to X, Y or Z,
in the link's axes, and its origin `localPose0` turned back by `localRot1`. So a URDF whose
link frames a converter kept reads back with those frames. A joint written child-first (its
body0 further from the root) is turned round: the frames swap and its axis flips, its limits
stay. The source check
(check/source/usd/) applies the same rule to usd-core's own physics parser.

Joints: Revolute (limits in degrees -> rad; none or infinite: continuous), Prismatic (m),
Fixed, Spherical (the translation's three revolute joints); effort and velocity as
limits.py reads them (`simkit:effortLimit`, else the drive's `maxForce`; PhysX's
`maxJointVelocity` or Newton's `velocityLimit`, deg/s); damping, friction loss and armature
as dynamics.py reads them (MjcPhysics, PhysX's armature; other Physics variants fill gaps);
a follower's `<mimic>` as mimic.py reads it (NewtonMimicAPI, PhysxMimicJointAPI).
A joint with no body0 (or a body0 that is no rigid body) joins the robot to the world: on
the root body a fixed one bolts the base (a `world` link), another moves it.
Other joint types are read as fixed and listed; a drive's stiffness and damping are not read
(the kit sizes its own servos). A joint with `excludeFromArticulation`, or one closing a
loop (a body's second parent joint, in the stage's order), is emitted after the tree, so the
translation's `second_parents` (translate/loops.py) leaves it out (listed as dropped).

Mass: MassAPI `mass` (kg), `centerOfMass`, `diagonalInertia` and `principalAxes` in the body
frame; where the mass is not authored, the collision shapes' solid at the MassAPI `density`
(else 1000 kg/m^3, UsdPhysics' default), its CoM and inertia where those are not authored;
all scaled to MjcPhysics' `setTotalMass` where the stage sets it (mjc.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from simkit.importer.formats.usd import dynamics, limits, mimic, mjc, poses, shapes
from simkit.importer.formats.usd.stage import Articulation, ends, stage_names
from simkit.importer.read.model import At, Dynamics, Joint, Limit, Link, Robot

#: |limit| at or above which a bound means none (USD writes +-inf or FLT_MAX)
UNBOUNDED = 1e30
KINDS = {
    "PhysicsRevoluteJoint": "revolute",
    "PhysicsPrismaticJoint": "prismatic",
    "PhysicsFixedJoint": "fixed",
    "PhysicsSphericalJoint": "spherical",
}
WORLD = "world"


@dataclass
class Context:
    """What the tree is built from: the articulation, the stage's units, an XformCache, the
    scratch folder for meshes, the link names by body path, the listed differences."""

    art: Articulation
    units: poses.Units
    cache: object
    scratch: Path
    names: dict[str, str] = field(default_factory=dict)
    listed: list[tuple[str, str]] = field(default_factory=list)
    dropped: list[tuple[object, str]] = field(default_factory=list)
    #: further root bodies -> the fixed joint bolting each to the world
    bolts: dict = field(default_factory=dict)
    #: massless links added between the joints of one pair of bodies (_chain)
    added: list[str] = field(default_factory=list)
    #: id(joint) -> its frame's turn in the child's body axes (the axis is turned by it)
    turns: dict[int, np.ndarray] = field(default_factory=dict)
    #: joint name -> its drive's force (N m or N) where the joint has its own effort limit
    servos: dict[str, float] = field(default_factory=dict)
    #: joint name -> its armature (kg m^2 or kg) where the USD gives one (dynamics.py)
    armatures: dict[str, float] = field(default_factory=dict)
    #: the stage composed with each other Physics variant, made on first need (dynamics.py)
    others: list | None = None
    #: (where, why) report lines of mimics read as independent (mimic.py)
    notes: list[tuple[str, str]] = field(default_factory=list)


def local_pose(joint, end: int, ctx: Context) -> np.ndarray:
    """The joint frame on body `end` (0 or 1) in that body's frame (m; the body's world
    scale applied to `localPos`, as PhysX applies it)."""
    pos = poses.get(joint, f"physics:localPos{end}")
    rot = poses.get(joint, f"physics:localRot{end}")
    body = ends(joint)[end]
    scale = np.ones(3)
    if body:
        prim = ctx.art.stage.GetPrimAtPath(body)
        if prim:
            scale = poses.world(ctx.cache, prim, 1.0)[1]
    at = np.zeros(3) if pos is None else np.asarray(pos, dtype=float) * scale
    turn = np.eye(3) if rot is None else poses.quat_matrix(rot)
    return poses.make(turn, at * ctx.units.meters)


@dataclass
class Built:
    """The model's links and joints as the tree adds them, in the stage's order."""

    links: list[Link] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)

    def taken(self) -> set[str | None]:
        return {link.name for link in self.links} | {joint.name for joint in self.joints}


def to_robot(art: Articulation, scratch: Path) -> tuple[Robot, bool, list, list, Context]:
    """(the source model, floating base, listed (what, reason), dropped (joint prim, why),
    the context: its `servos`, the drive forces apart from the joints' effort limits, and
    `armatures`, {joint name: N m or N, kg m^2 or kg})."""
    from pxr import UsdGeom

    ctx = Context(art, poses.Units.of(art.stage), UsdGeom.XformCache(), scratch)
    every = stage_names(art.stage)
    ctx.names = {body: every["links"][body] for body in art.bodies}
    joint_names = every["joints"]
    name = art.root_prim.GetName() or "robot"
    built = Built()
    root = str(art.root_prim.GetPath())
    frames, order, loops, (base, world) = _walk(art, root, ctx)
    floating = base is None
    if base is not None:
        built.links.append(_bare(WORLD))
        origin = _world_origin(base, ctx)
        order = [*_chain(base, world, WORLD, ctx.names[root], False, origin, ctx), *order]
        for body, joint in sorted(ctx.bolts.items()):
            bolt = (joint, WORLD, ctx.names[body], False, _world_origin(joint, ctx))
            order.insert(1, bolt)
    bodies = [_link(body, frames[body], ctx) for body in art.bodies if body in frames]
    built.links += mjc.scale_to_total(bodies, art, ctx.units.kilograms, ctx.listed)
    for kind in ("links", "joints"):
        for path in art.apart.get(kind, []):
            why = "the scene's, not joined to the robot: not imported"
            ctx.listed.append((f"{kind}.{every[kind][path]}", why))
    built.links += [_bare(added) for added in ctx.added]
    for joint, parent, child, flip, origin in order:
        built.joints.append(_joint(joint, joint_names, (parent, child), origin, ctx, flip))
    for body in art.bodies:
        if body in frames:
            _frames(built, body, frames[body], ctx)
    for joint in loops:
        a, b = ends(joint)
        if a in ctx.names and b in ctx.names:
            there = local_pose(joint, 1, ctx)
            ctx.turns[id(joint)] = there[:3, :3]
            origin = poses.inv(frames.get(a, np.eye(4))) @ local_pose(joint, 0, ctx)
            origin = origin @ _turn_back(there)
            ends_ = (ctx.names[a], ctx.names[b])
            built.joints.append(_joint(joint, joint_names, ends_, origin, ctx))
        else:
            ctx.dropped.append((joint, "joins the robot to the world away from its root"))
    _list_left_out(art, frames, every, ctx)
    links, joints = tuple(built.links), tuple(built.joints)
    materials = tuple(g.material for link in links for g in link.visuals if g.material)
    robot = Robot(At("robot", name), name, links, joints, materials)
    return robot, floating, ctx.listed, ctx.dropped, ctx


def _bare(name: str) -> Link:
    """A link with nothing in it (the world, an added or a frame link)."""
    return Link(name, At("link", name))


def _list_left_out(art: Articulation, frames: dict, every: dict, ctx: Context) -> None:
    """List the bodies the tree does not reach (joined to it only by a joint outside the
    articulation: a MuJoCo mocap body's weld) and the joints dropped, as the source check
    names them: it reads the whole stage and fails on what the kit lacks unlisted."""
    for body in art.bodies:
        if body not in frames:
            why = "joined to the robot only by a joint outside the articulation: not imported"
            ctx.listed.append((f"links.{every['links'][body]}", why))
    for joint, why in ctx.dropped:
        name = every["joints"].get(str(joint.GetPath()))
        if name:
            ctx.listed.append((f"joints.{name}", f"not imported: {why}"))


def _walk(art: Articulation, root: str, ctx: Context):
    """Breadth-first from the root body: each body's link frame (in its body frame), the
    tree joints (joint, parent, child, flipped, origin), the loop joints, the base joint."""
    from pxr import UsdPhysics

    bodies = set(art.bodies)
    frames: dict[str, np.ndarray] = {}
    base, loops, order = None, [], []
    tree_joints, claimed, extras, bolts = [], {}, {}, {}
    for joint in art.joints:
        a, b = ends(joint)
        excluded = bool(UsdPhysics.Joint(joint).GetExcludeFromArticulationAttr().Get())
        world = (a not in bodies) != (b not in bodies)
        if world and b in art.more_roots and b not in bolts and not excluded:
            bolts[b] = joint  # a further articulation of the robot, bolted to the world
        elif world and base is None and root in (a, b) and not excluded:
            base = joint
        elif world and base is not None and b == root == ends(base)[1] and not excluded:
            extras.setdefault(id(base), []).append(joint)  # more DOF between world and root
        elif not (world or excluded) and b in claimed and ends(claimed[b])[0] == a:
            extras.setdefault(id(claimed[b]), []).append(joint)  # one more DOF, the same pair
        elif world or excluded or b in claimed:
            loops.append(joint)  # a body's second parent joint (stage order) closes a loop
        else:
            claimed[b] = joint
            tree_joints.append(joint)
    frames[root] = np.eye(4)
    if base is not None:
        end = 1 if ends(base)[1] == root else 0
        last = (extras.get(id(base)) or [base])[-1]
        frames[root] = _at(local_pose(last, end, ctx))
    for body, joint in bolts.items():
        frames[body] = _at(local_pose(joint, 1, ctx))
    ctx.bolts = bolts
    todo, used = [root, *sorted(bolts)], set()
    while todo:
        body = todo.pop(0)
        for joint in tree_joints:
            a, b = ends(joint)
            if id(joint) in used or body not in (a, b):
                continue
            other, flip = (b, False) if a == body else (a, True)
            if other in frames:
                continue
            used.add(id(joint))
            near, far = (1, 0) if flip else (0, 1)
            there = local_pose(joint, far, ctx)
            origin = poses.inv(frames[body]) @ local_pose(joint, near, ctx) @ _turn_back(there)
            frames[other] = _at(there)
            ctx.turns[id(joint)] = there[:3, :3]
            chain = [] if flip else extras.pop(id(joint), [])
            loops += extras.pop(id(joint), [])  # a turned-round pair's further joints
            order += _chain(joint, chain, ctx.names[body], ctx.names[other], flip, origin, ctx)
            if chain:
                frames[other] = _at(local_pose(chain[-1], 1, ctx))
            todo.append(other)
    loops += [j for j in tree_joints if id(j) not in used]
    world = extras.pop(id(base), []) if base is not None else []
    loops += [j for rest in extras.values() for j in rest]
    return frames, order, loops, (base, world)


def _chain(first, rest: list, parent: str, child: str, flip: bool, origin, ctx: Context):
    """Order entries (joint, parent link, child link, flipped, origin) of the joints between
    one pair of bodies: one joint, or several (a body with several degrees of freedom, as
    MJCF writes it and mujoco-usd-converter keeps it) made a chain through added massless
    links `JOINT_link`, each joint turning about its own frame on body1, in the stage's
    order (as authored: an MJCF body's joint order)."""
    if not rest:
        return [(first, parent, child, flip, origin)]
    joints = [first, *rest]
    out, at = [], parent
    for k, joint in enumerate(joints):
        pose = local_pose(joint, 1, ctx)
        if k:
            ctx.turns[id(joint)] = pose[:3, :3]
            before = local_pose(joints[k - 1], 1, ctx)[:3, 3]
            origin = poses.make(np.eye(3), pose[:3, 3] - before)
        to = child if k == len(joints) - 1 else _added(f"{joint.GetName()}_link", ctx)
        out.append((joint, at, to, False, origin))
        at = to
    return out


def _added(want: str, ctx: Context) -> str:
    """A new massless link's name, unique among the body names and those added."""
    taken = set(ctx.names.values()) | set(ctx.added)
    name, n = want, 1
    while name in taken:
        name, n = f"{want}_{n}", n + 1
    ctx.added.append(name)
    why = "added: a link between two joints of one pair of USD bodies"
    ctx.listed.append((f"links.{name}", why))
    return name


def _frames(built: Built, body: str, frame: np.ndarray, ctx: Context) -> None:
    """Each Xform directly under the body with no shape and no body below it (a tool or
    sensor frame): a massless link on a fixed joint `NAME_joint`, at its pose (m)."""
    from pxr import Usd

    prim = ctx.art.stage.GetPrimAtPath(body)
    taken = built.taken()
    every = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
    for child in prim.GetFilteredChildren(every):
        if child.GetTypeName() != "Xform" or str(child.GetPath()) in ctx.names:
            continue
        below = list(Usd.PrimRange(child, every))
        if any(p.GetTypeName() in shapes.SHAPES or str(p.GetPath()) in ctx.names for p in below):
            continue
        name, n = child.GetName(), 0
        while name in taken or f"{name}_joint" in taken:
            n += 1
            name = f"{child.GetName()}_{n}"
        joint_name = f"{name}_joint"
        taken |= {name, joint_name}
        pose = poses.relative(ctx.cache, child, prim, ctx.units.meters)
        pose = poses.inv(frame) @ shapes.rigid(pose)[0]
        at = At("joint", joint_name)
        origin = poses.pose(pose)
        built.joints.append(Joint(joint_name, "fixed", at, ctx.names[body], name, origin))
        built.links.append(_bare(name))


def _world_origin(joint, ctx: Context) -> np.ndarray:
    """The world joint's frame in the world (m, Z up): its non-body end's world pose (the
    world itself when unset) times that end's local pose."""
    a, b = ends(joint)
    end, other = (0, a) if b in ctx.names else (1, b)
    at = np.eye(4)
    prim = ctx.art.stage.GetPrimAtPath(other) if other else None
    if prim:
        at = poses.world(ctx.cache, prim, ctx.units.meters)[0]
    up = poses.make(ctx.units.up, np.zeros(3))
    return up @ at @ local_pose(joint, end, ctx) @ _turn_back(local_pose(joint, 1 - end, ctx))


def _at(pose: np.ndarray) -> np.ndarray:
    """The link frame a joint frame gives its body: moved to the joint, not turned."""
    return poses.make(np.eye(3), pose[:3, 3])


def _turn_back(pose: np.ndarray) -> np.ndarray:
    """The inverse of a joint frame's turn: the joint's origin then ends in the link's axes."""
    return poses.make(pose[:3, :3].T, np.zeros(3))


def _link(body: str, frame: np.ndarray, ctx: Context) -> Link:
    """The body's link with its inertial (MassAPI, else the colliders' solid) and shapes."""
    from simkit.importer.formats.usd import mass

    prim = ctx.art.stage.GetPrimAtPath(body)
    name = ctx.names[body]
    found = shapes.shapes(name, prim, set(ctx.art.bodies), frame, ctx)
    for how in sorted(set(found.approximations) - {"none"}):
        why = f"a mesh collider's approximation '{how}': the kit makes its own convex pieces"
        ctx.listed.append((f"links.{name}.collision", why))
    solid = mass.of_body(prim, name, found.colliders, frame, ctx)
    collisions = tuple(c.geometry for c in found.colliders)
    return Link(name, At("link", name), mass.inertial(solid), tuple(found.visuals), collisions)


def _joint(joint, names, link_names, origin, ctx: Context, flip: bool = False) -> Joint:
    """The `Joint` of a UsdPhysics joint between two links (flipped: written child-first)."""
    kind = KINDS.get(joint.GetTypeName())
    name = names[str(joint.GetPath())]
    if kind is None:
        why = f"a {joint.GetTypeName() or 'generic'} joint: read as fixed"
        ctx.listed.append((f"joints.{name}.type", why))
        kind = "fixed"
    out = Joint(name, kind, At("joint", name), *link_names, poses.pose(origin))
    if kind in ("revolute", "prismatic"):
        out = _axis_limits(out, joint, flip, ctx)
        out = replace(out, mimic=mimic.of(joint, names, ctx.units, ctx.notes))
    if kind == "spherical":
        ctx.listed.append((f"joints.{name}.limits", "a spherical joint's cone limits: not read"))
    return out


def _axis_limits(out: Joint, joint, flip: bool, ctx: Context) -> Joint:
    """Axis (joint frame; flipped with the joint), limits (rad or m), effort, velocity."""
    kind = out.type
    axis = np.zeros(3)
    axis["XYZ".index(str(joint.GetAttribute("physics:axis").Get() or "X"))] = -1.0 if flip else 1.0
    axis = ctx.turns.get(id(joint), np.eye(3)) @ axis
    axis = poses.floats(np.where(np.abs(axis) < 1e-15, 0.0, axis))
    low = poses.get(joint, "physics:lowerLimit")
    high = poses.get(joint, "physics:upperLimit")
    bounded = all(v is not None and abs(float(v)) < UNBOUNDED for v in (low, high))
    scale = math.radians(1.0) if kind == "revolute" else ctx.units.meters
    limit: dict[str, float] = {}
    if bounded:
        limit = {"lower": float(low) * scale, "upper": float(high) * scale}
    elif kind == "revolute":
        out = replace(out, type="continuous")
    force = limits.effort(joint, kind, ctx.units)
    if force is not None:
        limit["effort"] = float(force)
    servo = limits.servo_force(joint, kind, ctx.units)
    if servo is not None:
        ctx.servos[out.name] = servo
    speed = limits.velocity(joint, kind)
    if speed is not None:
        limit["velocity"] = float(speed * scale)
    found = Limit(At("limit"), **limit) if limit else None
    return replace(
        out,
        axis=axis,
        axis_at=At("axis"),
        limit=found,
        dynamics=_dynamics(out.name, joint, kind, ctx),
    )


def _dynamics(name: str, joint, kind: str, ctx: Context) -> Dynamics | None:
    """The joint's `Dynamics`, and its armature (kept for the spec), as dynamics.py reads
    them."""
    if ctx.others is None:
        ctx.others = dynamics.variant_stages(ctx.art.stage, ctx.art.variant)
    found = dynamics.of_joint(joint, kind, ctx.units, ctx.others)
    if "armature" in found:
        ctx.armatures[name] = found["armature"]
    return dynamics.model(found)
