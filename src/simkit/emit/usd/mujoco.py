"""`mujoco.usda`: the MuJoCo additions of the "mujoco" variant, over `physics.usda`, in
MuJoCo's own USD schemas (MjcPhysics, as MuJoCo's USD importer, Newton's `SchemaResolverMjc`
and NVIDIA's mujoco-usd-converter read them). The values are the kit's MJCF ones:

- every movable joint carries `MjcJointAPI`: `mjc:armature` (kg m^2 or kg), `mjc:damping`
  (N m s/rad or N s/m), `mjc:frictionloss` (N m or N) and, for a spring, `mjc:stiffness`
  (N m/rad or N/m) and `mjc:springref` (degrees for a revolute joint, as MjcPhysics reads
  angles when no scene says otherwise; m for a prismatic one);
- every servo is an `MjcActuator` prim under `/NAME/actuators`, named as its joint, targeting
  it (`mjc:target`): MuJoCo's position servo, gain kp, affine bias (0, -kp, -kv) (10 values
  each, as MuJoCo stores them), the control
  range the joint's range (rad or m) and the force range +-forcerange (N m or N).

UsdPhysics has no field for these, and the PhysX layer's armature is PhysX's own, so they live
in their own layer: a MuJoCo reader takes the "mujoco" variant and gets the kit's MJCF
dynamics; every other reader never sees them. MjcPhysics is not registered with usd-core, so
the schema and attribute names are authored as plain tokens (as `PhysicsJointStateAPI` is)."""

from __future__ import annotations

import math

from simkit.emit.usd.common import export, new_stage, prim_name
from simkit.kitio.fmt import rounded
from simkit.model.robot import Joint, Robot

#: length of MuJoCo's gain and bias parameter vectors (mjNGAIN, mjNBIAS), as readers expect
PRM = 10


def _joint_values(joint: Joint) -> dict[str, float]:
    """mjc: joint attribute -> value, in MuJoCo's units (springref in degrees, revolute)."""
    values = {
        "mjc:armature": joint.armature,
        "mjc:damping": joint.damping,
        "mjc:frictionloss": joint.friction,
    }
    if joint.stiffness:
        angular = joint.type != "prismatic"
        values["mjc:stiffness"] = joint.stiffness
        values["mjc:springref"] = math.degrees(joint.springref) if angular else joint.springref
    return values


def _set(prim, name: str, type_name, value) -> None:
    from pxr import Sdf

    attr = prim.CreateAttribute(name, type_name, custom=False)
    attr.SetVariability(Sdf.VariabilityUniform)
    attr.Set(value)


def _actuator(stage, root: str, robot: Robot, act) -> None:
    """One MuJoCo position servo as an MjcActuator prim."""
    from pxr import Sdf, Vt

    joint = robot.joint(act.joint)
    prim = stage.DefinePrim(f"{root}/actuators/{prim_name(act.joint)}", "MjcActuator")
    prim.CreateRelationship("mjc:target", custom=False).SetTargets(
        [f"{root}/joints/{prim_name(act.joint)}"]
    )
    doubles = Sdf.ValueTypeNames.DoubleArray
    _set(prim, "mjc:gainType", Sdf.ValueTypeNames.Token, "fixed")
    gain, bias = [0.0] * PRM, [0.0] * PRM  # MuJoCo's actuator_gainprm, actuator_biasprm
    gain[0], bias[1], bias[2] = rounded(act.kp), -rounded(act.kp), -rounded(act.kv)
    _set(prim, "mjc:gainPrm", doubles, Vt.DoubleArray(gain))
    _set(prim, "mjc:biasType", Sdf.ValueTypeNames.Token, "affine")
    _set(prim, "mjc:biasPrm", doubles, Vt.DoubleArray(bias))
    if joint.lower is not None and joint.type != "continuous":
        _set(prim, "mjc:ctrlLimited", Sdf.ValueTypeNames.Token, "true")
        _set(prim, "mjc:ctrlRange:min", Sdf.ValueTypeNames.Double, rounded(joint.lower))
        _set(prim, "mjc:ctrlRange:max", Sdf.ValueTypeNames.Double, rounded(joint.upper))
    _set(prim, "mjc:forceLimited", Sdf.ValueTypeNames.Token, "true")
    _set(prim, "mjc:forceRange:min", Sdf.ValueTypeNames.Double, -rounded(act.forcerange))
    _set(prim, "mjc:forceRange:max", Sdf.ValueTypeNames.Double, rounded(act.forcerange))


def mujoco_text(robot: Robot) -> str:
    """The `mujoco.usda` text."""
    from pxr import Sdf

    name = prim_name(robot.name)
    root = f"/{name}"
    layer, stage, _top = new_stage(robot, name, over=True)
    for joint in robot.joints:
        if not joint.movable:
            continue
        prim = stage.OverridePrim(f"{root}/joints/{prim_name(joint.name)}")
        prim.AddAppliedSchema("MjcJointAPI")
        for attr, value in _joint_values(joint).items():
            _set(prim, attr, Sdf.ValueTypeNames.Double, rounded(value))
    if robot.actuators:
        stage.DefinePrim(f"{root}/actuators", "Scope")
    for act in robot.actuators:
        _actuator(stage, root, robot, act)
    return export(layer)
