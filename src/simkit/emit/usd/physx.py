"""`physx.usda`: the PhysX additions of the "physx" variant, over `physics.usda`. Per movable
joint, PhysxJointAxisAPI carries what the spec gives and UsdPhysics has no field for: the
rotor inertia reflected to the joint (armature, kg m^2 or kg, as MJCF's `armature`) and the
joint speed limit (`maxJointVelocity`, deg/s or m/s). Only `physxJointAxis:` values live here,
so the UsdPhysics agreement is the same in both physics variants."""

from __future__ import annotations

import math

from simkit.emit.usd.common import export, new_stage, prim_name
from simkit.kitio.fmt import rounded
from simkit.model.robot import Robot


def physx_text(robot: Robot) -> str:
    """The `physx.usda` text."""
    from pxr import Sdf

    name = prim_name(robot.name)
    layer, stage, _top = new_stage(robot, name, over=True)
    for joint in robot.joints:
        if not joint.movable:
            continue
        if not (joint.armature or joint.max_velocity):
            continue
        prim = stage.OverridePrim(f"/{name}/joints/{prim_name(joint.name)}")
        angular = joint.type != "prismatic"
        kind = "angular" if angular else "linear"
        prim.AddAppliedSchema(f"PhysxJointAxisAPI:{kind}")
        values = {"armature": joint.armature}
        if joint.max_velocity:
            values["maxJointVelocity"] = (
                math.degrees(joint.max_velocity) if angular else joint.max_velocity
            )
        for what, value in values.items():
            attr = prim.CreateAttribute(
                f"physxJointAxis:{kind}:{what}", Sdf.ValueTypeNames.Float, custom=False
            )
            attr.Set(rounded(value))
    return export(layer)
