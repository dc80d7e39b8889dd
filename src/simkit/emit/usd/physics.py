"""`physics.usda`: the UsdPhysics payload (the "physics" variant; the "physx" variant adds
`physx.usda` on top). Over the base hierarchy it applies a rigid body and MassAPI per link,
colliders on the `collisions` pieces, and the articulation root on `/NAME`; it defines the
joints under `/NAME/joints`, with DriveAPI and joint state, and Isaac Sim's robot schema
(robot_schema.py). Every `physics:` value lives in this layer, as the SimReady rules RC.005
and RC.006 ask.

Joints: the frame of each joint is the child link frame, turned so the joint axis is the
schema's X/Y/Z token; limits and drive gains follow the UsdPhysics units (degrees for angular
joints). A joint from the root frame targets `/NAME` itself, so the robot stays fixed to
wherever the asset is placed; a floating base has no such joint. Where a massless root frame
holds several links by fixed joints (a mobile manipulator's base_footprint: its base_link and a
cover link), only the first is fixed to `/NAME`; the others are fixed to that first link at the
same place, since UsdPhysics parsers start one articulation per body fixed to the world."""

from __future__ import annotations

import math

import numpy as np

from simkit.emit.usd.common import (
    axis_frame,
    collision_pieces,
    export,
    new_stage,
    piece_name,
    prim_name,
    quatf,
    r,
)
from simkit.emit.usd.mimic import apply_mimic, driven_follower
from simkit.emit.usd.robot_schema import apply_robot_schema
from simkit.kitio.fmt import rounded
from simkit.model.inertia import principal_axes
from simkit.model.kinematics import excluded_pairs, jointed_pairs, rpy_matrix
from simkit.model.robot import Joint, Link, Loop, Robot

#: the joint's effort limit (URDF `<limit effort>`), apart from the drive's maxForce
EFFORT_LIMIT = "simkit:effortLimit"
EFFORT_DOC = (
    "The joint's effort limit (URDF limit effort): N m for a revolute joint, N for a"
    " prismatic one. Not read by simulators: the drive's maxForce is the force they apply."
)


def _mass(prim, link: Link) -> None:
    from pxr import Gf, UsdPhysics

    api = UsdPhysics.MassAPI.Apply(prim)
    inertial = link.inertial
    if inertial is None:
        api.CreateMassAttr(rounded(link.mass))
        return
    diag, axes = principal_axes(inertial.tensor())
    api.CreateMassAttr(rounded(inertial.mass))
    api.CreateCenterOfMassAttr(Gf.Vec3f(*r(inertial.com)))
    api.CreateDiagonalInertiaAttr(Gf.Vec3f(*r(diag)))
    api.CreatePrincipalAxesAttr(quatf(axes))


def _link(stage, root: str, link: Link) -> None:
    from pxr import UsdPhysics

    base = f"{root}/{prim_name(link.name)}"
    prim = stage.OverridePrim(base)
    UsdPhysics.RigidBodyAPI.Apply(prim)
    _mass(prim, link)
    kind, pieces = collision_pieces(link)
    for i in range(len(pieces)):
        piece = stage.OverridePrim(f"{base}/collisions/{piece_name(i)}")
        UsdPhysics.CollisionAPI.Apply(piece)
        if kind == "meshes":
            UsdPhysics.MeshCollisionAPI.Apply(piece).CreateApproximationAttr(
                UsdPhysics.Tokens.convexHull
            )


def _anchor(robot: Robot) -> Joint | None:
    """The first fixed joint from the root frame: its child is the one link fixed to `/NAME`
    (None when no fixed joint leaves the root frame)."""
    return next((j for j in robot.joints if j.parent == robot.root and j.type == "fixed"), None)


def _schema(stage, path: str, joint: Joint):
    from pxr import UsdPhysics

    if joint.type in ("revolute", "continuous"):
        return UsdPhysics.RevoluteJoint.Define(stage, path)
    if joint.type == "prismatic":
        return UsdPhysics.PrismaticJoint.Define(stage, path)
    return UsdPhysics.FixedJoint.Define(stage, path)


def _joint(stage, root: str, robot: Robot, joint: Joint, anchor: Joint | None) -> str:
    """Define one joint; returns its path."""
    from pxr import Gf

    path = f"{root}/joints/{prim_name(joint.name)}"
    schema = _schema(stage, path, joint)
    body0 = root if joint.parent == robot.root else f"{root}/{prim_name(joint.parent)}"
    token, turn = axis_frame(joint.axis) if joint.movable else ("X", np.eye(3))
    xyz, rot = np.asarray(joint.xyz, dtype=float), rpy_matrix(joint.rpy)
    if anchor is not None and joint.type == "fixed" and joint.parent == robot.root:
        # the joint frame in the anchor link's frame: inv(T_root_anchor) @ T_root_joint
        body0 = f"{root}/{prim_name(anchor.child)}"
        rot_a = rpy_matrix(anchor.rpy)
        xyz, rot = rot_a.T @ (xyz - np.asarray(anchor.xyz, dtype=float)), rot_a.T @ rot
    schema.CreateBody0Rel().SetTargets([body0])
    schema.CreateBody1Rel().SetTargets([f"{root}/{prim_name(joint.child)}"])
    schema.CreateLocalPos0Attr(Gf.Vec3f(*r(xyz)))
    schema.CreateLocalRot0Attr(quatf(rot @ turn))
    schema.CreateLocalPos1Attr(Gf.Vec3f(0.0, 0.0, 0.0))
    schema.CreateLocalRot1Attr(quatf(turn))
    if joint.movable:
        schema.CreateAxisAttr(token)
        _limits_and_drive(schema, robot, joint)
    if joint.mimic is not None and not driven_follower(robot, joint):
        apply_mimic(schema.GetPrim(), robot, joint)
    return path


def _limits_and_drive(schema, robot: Robot, joint: Joint) -> None:
    from pxr import Sdf, UsdPhysics

    angular = joint.type != "prismatic"
    # UsdPhysics: angular limits in degrees, linear limits in distance units (m)
    unit = math.degrees if angular else float
    if joint.type != "continuous" and joint.lower is not None and joint.upper is not None:
        schema.CreateLowerLimitAttr(rounded(unit(joint.lower)))
        schema.CreateUpperLimitAttr(rounded(unit(joint.upper)))
    kind = "angular" if angular else "linear"
    prim = schema.GetPrim()
    # joint state (the PhysX schema's PhysicsJointStateAPI, read by Isaac Sim and the SimReady
    # rule DJ.002): position (deg or m) and velocity at rest, q = 0 as the base pose
    prim.AddAppliedSchema(f"PhysicsJointStateAPI:{kind}")
    for what in ("position", "velocity"):
        attr = prim.CreateAttribute(f"state:{kind}:physics:{what}", Sdf.ValueTypeNames.Float)
        attr.Set(0.0)
    _effort_limit(prim, joint)
    actuator, target = next((a for a in robot.actuators if a.joint == joint.name), None), 0.0
    if actuator is None and joint.mimic is not None:
        if not driven_follower(robot, joint):
            return  # the mimic owns the DOF: no drive, not even a passive damper (DJ.004)
        # PhysX does not enforce a linear mimic: the follower carries its leader's servo, aimed
        # where the mimic puts it while the leader holds its target 0 (the offset, m)
        actuator = next((a for a in robot.actuators if a.joint == joint.mimic[0]), None)
        target = joint.mimic[2]
    # UsdPhysics DriveAPI angular gains are per degree (stiffness N m/deg, damping N m s/deg)
    # and its target position is in degrees.
    per = math.pi / 180.0 if angular else 1.0
    if actuator is not None:
        # MJCF position servo: tau = kp (q_ref - q) - kv qdot, |tau| <= forcerange.
        gains, max_force = (actuator.kp, actuator.kv), actuator.forcerange
    elif joint.stiffness or joint.damping:
        # A passive spring-damper (MJCF joint stiffness, springref, damping; e.g. Asimov's toes,
        # 001_71a395c46b8a5939.txt "Toe Joints"): tau = -k (q - springref) - d qdot is a force
        # drive aimed at springref with no force limit (maxForce left at its default, inf).
        gains, max_force = (joint.stiffness, joint.damping), None
        target = math.degrees(joint.springref) if angular else joint.springref
    else:
        return
    drive = UsdPhysics.DriveAPI.Apply(prim, kind)
    drive.CreateTypeAttr("force")
    drive.CreateStiffnessAttr(rounded(gains[0] * per))
    drive.CreateDampingAttr(rounded(gains[1] * per))
    if max_force is not None:
        drive.CreateMaxForceAttr(rounded(max_force))
    drive.CreateTargetPositionAttr(rounded(target))


def _effort_limit(prim, joint: Joint) -> None:
    """`simkit:effortLimit`: the joint's effort limit (the URDF `<limit effort>`, the spec's
    effort_peak; N m or N, in the stage's units as the drive's maxForce). UsdPhysics, PhysX,
    Isaac's robot schema and Newton's have no field for it (the drive's maxForce is the
    servo's force, which simulators enforce; urdf-usd-converter's concept mapping lists the
    effort as a gap), so it is a custom attribute that no simulator reads, and the USD
    import reads the joint's effort from it."""
    from pxr import Sdf

    if joint.effort_peak is None:
        return
    attr = prim.CreateAttribute(EFFORT_LIMIT, Sdf.ValueTypeNames.Float, custom=True)
    attr.SetDocumentation(EFFORT_DOC)
    attr.Set(rounded(joint.effort_peak))


def _filtered_pairs(stage, root: str, robot: Robot) -> None:
    """Joints already ignore contacts between the two bodies they join; the explicit pair
    matches the MJCF <exclude> for readers that merge or drop fixed joints (and the pairs in
    contact in every configuration, collision_pairs.always_pairs, and the spec's declared
    `contact_excludes`)."""
    from pxr import UsdPhysics

    targets: dict[str, list[str]] = {}
    for parent, child in [*jointed_pairs(robot), *excluded_pairs(robot)]:
        targets.setdefault(child, []).append(f"{root}/{prim_name(parent)}")
    for child, paths in targets.items():
        api = UsdPhysics.FilteredPairsAPI.Apply(stage.GetPrimAtPath(f"{root}/{prim_name(child)}"))
        api.CreateFilteredPairsRel().SetTargets(paths)


def physics_text(robot: Robot) -> str:
    """The `physics.usda` text."""
    from pxr import UsdPhysics

    name = prim_name(robot.name)
    root = f"/{name}"
    layer, stage, top = new_stage(robot, name, over=True)
    UsdPhysics.ArticulationRootAPI.Apply(top)
    for link in robot.links:
        _link(stage, root, link)
    _filtered_pairs(stage, root, robot)
    stage.DefinePrim(f"{root}/joints", "Scope")
    anchor = _anchor(robot)
    joints = []
    for joint in robot.joints:
        if joint.type == "floating":
            continue  # a free base body: UsdPhysics has no joint to the world for it
        joints.append(_joint(stage, root, robot, joint, None if joint is anchor else anchor))
    for loop in robot.loops:
        _loop_joint(stage, root, robot, loop)
    apply_robot_schema(stage, top, robot, joints)
    return export(layer)


def _loop_joint(stage, root: str, robot: Robot, loop: Loop) -> None:
    """A loop closure (spec `loops`) as UsdPhysics carries a loop: a FixedJoint excluded from
    the articulation (`physics:excludeFromArticulation`), holding `link2` at the loop's
    pose in `link1`'s frame (the root frame: `/NAME`, as a joint from the root)."""
    from pxr import Gf, UsdPhysics

    body0, body1 = (
        root if n == robot.root else f"{root}/{prim_name(n)}" for n in (loop.link1, loop.link2)
    )
    schema = UsdPhysics.FixedJoint.Define(stage, f"{root}/joints/{prim_name(loop.name)}")
    schema.CreateBody0Rel().SetTargets([body0])
    schema.CreateBody1Rel().SetTargets([body1])
    schema.CreateLocalPos0Attr(Gf.Vec3f(*r(loop.xyz)))
    schema.CreateLocalRot0Attr(quatf(rpy_matrix(loop.rpy)))
    schema.CreateLocalPos1Attr(Gf.Vec3f(0.0, 0.0, 0.0))
    schema.CreateLocalRot1Attr(quatf(np.eye(3)))
    schema.CreateExcludeFromArticulationAttr(True)
