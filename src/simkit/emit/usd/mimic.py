"""A mimic joint in `physics.usda`: PhysxMimicJointAPI, the coupling Isaac Sim reads and the
SimReady rules DJ.004 and DJ.007 ask for on a follower without a drive. It sits in the physics
layer, beside the joint state (also a PhysX schema), so both physics variants couple the
follower as the MJCF's joint equality does."""

from __future__ import annotations

from simkit.emit import mjcf_world
from simkit.emit.mjcf import MIMIC_TIMECONST_STEPS, TIMESTEP
from simkit.emit.usd.common import axis_frame, prim_name
from simkit.kitio.fmt import rounded
from simkit.model.robot import Joint, Robot


def apply_mimic(prim, robot: Robot, joint: Joint) -> None:
    """PhysX couples q + gearing q_leader + offset = 0 (PxArticulationMimicJoint), so a URDF
    mimic q = multiplier q_leader + offset has gearing -multiplier and offset -offset (rad or
    m). Its compliance is the MJCF equality's solref (timeconst, damping ratio 1): natural
    frequency 1 / timeconst (1/s), damping ratio 1."""
    from pxr import Sdf

    leader, multiplier, offset = joint.mimic
    lead = robot.joint(leader)
    instance = f"{_dof(joint)}{axis_frame(joint.axis)[0]}"
    prim.AddAppliedSchema(f"PhysxMimicJointAPI:{instance}")
    base = f"physxMimicJoint:{instance}"
    prim.CreateRelationship(f"{base}:referenceJoint", custom=False).SetTargets(
        [prim.GetPath().GetParentPath().AppendChild(prim_name(leader))]
    )
    axis = prim.CreateAttribute(f"{base}:referenceJointAxis", Sdf.ValueTypeNames.Token, False)
    axis.SetVariability(Sdf.VariabilityUniform)
    axis.Set(f"{_dof(lead)}{axis_frame(lead.axis)[0]}")
    timeconst = MIMIC_TIMECONST_STEPS * mjcf_world.timestep(robot, TIMESTEP)
    values = {
        "gearing": -multiplier,
        "offset": -offset,
        "naturalFrequency": 1.0 / timeconst,
        "dampingRatio": 1.0,
    }
    for what, value in values.items():
        attr = prim.CreateAttribute(f"{base}:{what}", Sdf.ValueTypeNames.Float, False)
        attr.Set(rounded(value))


def _dof(joint: Joint) -> str:
    return "trans" if joint.type == "prismatic" else "rot"
