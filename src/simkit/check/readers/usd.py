"""Read a USD file the way a USD physics consumer does: usd-core's validators, UsdPhysics' own
parser (or the schemas attribute by attribute on older usd-core), and forward kinematics
composed from the joints. Poses are 4x4, column convention, in the stage's world frame."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from simkit.model.kinematics import axis_angle, quat_matrix

MOVABLE = {"RevoluteJoint": "revolute", "PrismaticJoint": "prismatic"}


@dataclass(frozen=True)
class UsdJoint:
    """A joint as a USD physics reader sees it: body0 '' is the world; poses in body frames."""

    path: str
    kind: str  # revolute, prismatic, fixed
    body0: str
    body1: str
    pose0: np.ndarray
    pose1: np.ndarray
    axis: np.ndarray
    limit: tuple[float, float] | None  # deg (revolute) or m (prismatic)
    #: stiffness, damping, max force, target position (USD units: per degree, degrees)
    drive: tuple[float, float, float, float] | None


def prim_name(name: str) -> str:
    """The prim name USD gives a spec name (Tf.MakeValidIdentifier, as a USD writer must)."""
    from pxr import Tf

    return Tf.MakeValidIdentifier(name)


def matrix(pos, quat) -> np.ndarray:
    """4x4 column-convention transform from a Gf vector and Gf quaternion."""
    out = np.eye(4)
    out[:3, :3] = quat_matrix((quat.GetReal(), *quat.GetImaginary()))
    out[:3, 3] = list(pos)
    return out


def _axis(token) -> np.ndarray:
    return np.eye(3)["XYZ".index(str(token).rsplit(".", 1)[-1][-1])]


def validate(stage) -> tuple[list[str], int]:
    """(errors, warning count) from usd-core's validators (UsdValidation, the successor of
    UsdUtils.ComplianceChecker), or from the ComplianceChecker on older usd-core."""
    from pxr import UsdUtils

    try:
        from pxr import UsdValidation
    except ImportError:
        checker = UsdUtils.ComplianceChecker()
        checker.CheckCompliance(stage.GetRootLayer().realPath)
        return list(checker.GetErrors()) + list(checker.GetFailedChecks()), len(
            checker.GetWarnings()
        )
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    found = UsdValidation.ValidationContext(validators).Validate(stage)
    errors = [
        f"{e.GetName()}: {e.GetMessage()}"
        for e in found
        if e.GetType() == UsdValidation.ValidationErrorType.Error
    ]
    warns = sum(e.GetType() == UsdValidation.ValidationErrorType.Warn for e in found)
    return errors, int(warns)


def parse_physics(stage) -> dict | None:
    """UsdPhysics' parser output ({ObjectType: (paths, descs)}), or None if this usd-core has
    no parser (before 25.x)."""
    from pxr import UsdPhysics

    loader = getattr(UsdPhysics, "UsdPhysicsLoadStageFromPrimRange", None) or getattr(
        UsdPhysics, "LoadUsdPhysicsFromRange", None
    )
    if loader is None:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        return dict(loader(stage, ["/"]))


def joints_from_parser(parsed: dict) -> list[UsdJoint]:
    from pxr import UsdPhysics

    out = []
    for type_name, kind in (*MOVABLE.items(), ("FixedJoint", "fixed")):
        paths, descs = parsed.get(getattr(UsdPhysics.ObjectType, type_name), ([], []))
        for path, d in zip(paths, descs, strict=True):
            if d.excludeFromArticulation:
                continue  # a loop closure, not a tree joint (loop_joints)
            limit = drive = None
            if kind != "fixed":
                if d.limit.enabled:
                    limit = (float(d.limit.lower), float(d.limit.upper))
                if d.drive.enabled:
                    drive = (
                        float(d.drive.stiffness),
                        float(d.drive.damping),
                        float(d.drive.forceLimit),
                        float(d.drive.targetPosition),
                    )
            out.append(
                UsdJoint(
                    str(path),
                    kind,
                    str(d.body0),
                    str(d.body1),
                    matrix(d.localPose0Position, d.localPose0Orientation),
                    matrix(d.localPose1Position, d.localPose1Orientation),
                    _axis(d.axis) if kind != "fixed" else np.zeros(3),
                    limit,
                    drive,
                )
            )
    return out


def joints_from_schemas(stage) -> list[UsdJoint]:
    """The same records read attribute by attribute (usd-core without a physics parser);
    body0 may then be a non-body Xform, whose frame the FK takes from the stage."""
    from pxr import UsdPhysics

    out = []
    for prim in stage.Traverse():
        kind = {
            "PhysicsRevoluteJoint": "revolute",
            "PhysicsPrismaticJoint": "prismatic",
            "PhysicsFixedJoint": "fixed",
        }.get(str(prim.GetTypeName()))
        if kind is None:
            continue
        j = UsdPhysics.Joint(prim)
        if j.GetExcludeFromArticulationAttr().Get():
            continue  # a loop closure, not a tree joint (loop_joints)
        bodies = [j.GetBody0Rel().GetTargets(), j.GetBody1Rel().GetTargets()]
        limit = drive = None
        axis = np.zeros(3)
        if kind != "fixed":
            schema = (
                UsdPhysics.RevoluteJoint if kind == "revolute" else UsdPhysics.PrismaticJoint
            )(prim)
            axis = _axis(schema.GetAxisAttr().Get())
            lo, hi = schema.GetLowerLimitAttr().Get(), schema.GetUpperLimitAttr().Get()
            if lo is not None and hi is not None and math.isfinite(lo) and math.isfinite(hi):
                limit = (float(lo), float(hi))
            api = UsdPhysics.DriveAPI.Get(prim, "angular" if kind == "revolute" else "linear")
            if api and api.GetStiffnessAttr().HasAuthoredValue():
                drive = (
                    float(api.GetStiffnessAttr().Get()),
                    float(api.GetDampingAttr().Get()),
                    float(api.GetMaxForceAttr().Get()),
                    float(api.GetTargetPositionAttr().Get() or 0.0),
                )
        out.append(
            UsdJoint(
                str(prim.GetPath()),
                kind,
                *(str(b[0]) if b else "" for b in bodies),
                matrix(j.GetLocalPos0Attr().Get(), j.GetLocalRot0Attr().Get()),
                matrix(j.GetLocalPos1Attr().Get(), j.GetLocalRot1Attr().Get()),
                axis,
                limit,
                drive,
            )
        )
    return out


def loop_joints(stage) -> dict[str, tuple[str, str, np.ndarray, np.ndarray]]:
    """The joints excluded from the articulation (how USD carries a kinematic loop), by
    prim name: (body0 path, body1 path, localPose0, localPose1), read attribute by
    attribute."""
    from pxr import UsdPhysics

    out = {}
    for prim in stage.Traverse():
        if not prim.IsA(UsdPhysics.Joint):
            continue
        j = UsdPhysics.Joint(prim)
        if not j.GetExcludeFromArticulationAttr().Get():
            continue
        bodies = [j.GetBody0Rel().GetTargets(), j.GetBody1Rel().GetTargets()]
        out[prim.GetName()] = (
            *(str(b[0]) if b else "" for b in bodies),
            matrix(j.GetLocalPos0Attr().Get(), j.GetLocalRot0Attr().Get()),
            matrix(j.GetLocalPos1Attr().Get(), j.GetLocalRot1Attr().Get()),
        )
    return out


class UsdKinematics:
    """Poses of bodies and frames, composed from the USD joints at joint positions q (rad, m):
    T_w_body1 = T_w_body0 @ localPose0 @ motion(q) @ inv(localPose1)."""

    def __init__(self, stage, joints: list[UsdJoint]):
        from pxr import UsdGeom, UsdPhysics

        self.stage, self.joints = stage, joints
        cache = UsdGeom.XformCache()
        self.world = {}
        self.bodies = set()
        for prim in stage.Traverse():
            if prim.IsA(UsdGeom.Xformable):
                self.world[str(prim.GetPath())] = np.array(cache.GetLocalToWorldTransform(prim)).T
            if prim.HasAPI(UsdPhysics.RigidBodyAPI):
                self.bodies.add(str(prim.GetPath()))

    def poses(self, q: dict[str, float]) -> dict[str, np.ndarray]:
        """T_world_X for every body, from the joints; bodies no joint reaches keep their Xform."""
        out: dict[str, np.ndarray] = {"": np.eye(4)}
        moved = {j.body1 for j in self.joints}
        out.update({b: self.world[b] for b in self.bodies - moved})  # free (floating) bodies
        pending = list(self.joints)
        while pending:
            left = []
            for j in pending:
                if j.body0 not in out and j.body0 in self.bodies:
                    left.append(j)
                    continue
                start = out.get(j.body0, self.world.get(j.body0, np.eye(4)))
                motion = np.eye(4)
                value = q.get(j.path.rsplit("/", 1)[-1], 0.0)
                if j.kind == "revolute":
                    motion[:3, :3] = axis_angle(j.axis, value)
                elif j.kind == "prismatic":
                    motion[:3, 3] = j.axis * value
                out[j.body1] = start @ j.pose0 @ motion @ np.linalg.inv(j.pose1)
            if len(left) == len(pending):  # a loop of joints: not a tree
                raise ValueError(f"USD joints do not form a tree: {[j.path for j in left]}")
            pending = left
        return out

    def pose(self, poses: dict[str, np.ndarray], path: str) -> np.ndarray:
        """T_world_path: a body, or a frame carried by its nearest body ancestor."""
        node = path
        while node and node not in self.bodies:
            node = node.rsplit("/", 1)[0]
        if not node:
            return self.world[path]
        return poses[node] @ np.linalg.inv(self.world[node]) @ self.world[path]
