"""A mimic joint in `physics.usda`: PhysxMimicJointAPI, the coupling Isaac Sim reads and the
SimReady rules DJ.004 and DJ.007 ask for on a follower without a drive. It sits in the physics
layer, beside the joint state (also a PhysX schema), so both physics variants couple the
follower as the MJCF's joint equality does.

A prismatic follower is the exception: PhysX does not enforce a mimic on a linear DOF (the
SimReady rules DJ.004 and DJ.006 say so, and want the follower's own drive with stiffness to
hold it). Such a follower gets its leader's servo as its drive (physics.py) and no
PhysxMimicJointAPI, as Isaac Sim's own parallel grippers drive both fingers: an authored
coupling PhysX ignores would only mislead, and DJ.007's limit rule reads the gearing with the
opposite sign to PhysX's (q + gearing q_leader + offset = 0), so a finger on 0..a that follows
its leader with multiplier 1 could never pass it."""

from __future__ import annotations

import math

from simkit.emit import mjcf_world
from simkit.emit.mjcf import MIMIC_TIMECONST_STEPS, TIMESTEP
from simkit.emit.usd.common import axis_frame, prim_name
from simkit.kitio.fmt import rounded
from simkit.model.robot import Joint, Robot


def apply_mimic(prim, robot: Robot, joint: Joint) -> None:
    """PhysX couples q + gearing q_leader + offset = 0 (PxArticulationMimicJoint), so a URDF
    mimic q = multiplier q_leader + offset has gearing -multiplier and offset -offset, in the
    USD's units, as omni.physx reads them: the offset in degrees for an angular follower (m
    for a linear one), the gearing in follower units per leader unit (degrees for an angular
    joint, so 1:1 between two of a kind). Its compliance is the MJCF equality's solref
    (timeconst, damping ratio 1): natural frequency 1 / timeconst (1/s), damping ratio 1."""
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
        "gearing": -multiplier * _unit(joint) / _unit(lead),
        "offset": -offset * _unit(joint),
        "naturalFrequency": 1.0 / timeconst,
        "dampingRatio": 1.0,
    }
    for what, value in values.items():
        attr = prim.CreateAttribute(f"{base}:{what}", Sdf.ValueTypeNames.Float, False)
        attr.Set(rounded(value))


def driven_follower(robot: Robot, joint: Joint) -> bool:
    """A mimic follower that PhysX would not couple (a prismatic one) and whose leader has a
    servo to lend it: driven instead."""
    if joint.mimic is None or joint.type != "prismatic":
        return False
    return any(a.joint == joint.mimic[0] for a in robot.actuators)


def _unit(joint: Joint) -> float:
    """USD units per SI unit of the joint's coordinate: degrees per rad, or 1 (m)."""
    return 1.0 if joint.type == "prismatic" else math.degrees(1.0)


def _dof(joint: Joint) -> str:
    return "trans" if joint.type == "prismatic" else "rot"
