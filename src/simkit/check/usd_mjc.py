"""The "mujoco" variant's MjcPhysics values against the kit's MJCF loaded in MuJoCo: every
movable joint's `MjcJointAPI` (armature, damping, frictionloss, stiffness, springref) and one
`MjcActuator` per MuJoCo servo (target joint, gain, bias, control and force ranges). Read with
pxr from the composed stage, compared with MuJoCo's compiled model (the emitter is not
consulted)."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.readers.usd import prim_name
from simkit.check.usd_layout import applied

#: the physics variant that adds MuJoCo's MjcPhysics values (emit/usd/mujoco.py)
MJC_VARIANT = "mujoco"
#: mjc: joint attributes, in the order compared: MuJoCo's dof_armature, dof_damping,
#: dof_frictionloss, jnt_stiffness
JOINT_FIELDS = ("mjc:armature", "mjc:damping", "mjc:frictionloss", "mjc:stiffness")
RANGES = ("forceRange", "ctrlRange")
#: MuJoCo's one-DOF joints (a numpy int is not `in` a tuple of pybind11 enums)
MOVING = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))
#: relative tolerance: values are written as fmt.num prints them (10 significant digits)
REL = 1e-9


def _get(prim, name: str, default=0.0):
    attr = prim.GetAttribute(name)
    value = attr.Get() if attr and attr.HasAuthoredValue() else None
    return default if value is None else value


def _joint_rows(stage, root: str, mj) -> tuple[list, list, list[str]]:
    """(expected, actual, joints without MjcJointAPI) per MJCF hinge or slide joint."""
    exp, act, missing = [], [], []
    for j in range(mj.njnt):
        if int(mj.jnt_type[j]) not in MOVING:
            continue
        prim = stage.GetPrimAtPath(f"{root}/joints/{prim_name(mj.joint(j).name)}")
        if not prim or "MjcJointAPI" not in applied(prim):  # MjcPhysics: not registered
            missing.append(mj.joint(j).name)
            continue
        dof, qadr = int(mj.jnt_dofadr[j]), int(mj.jnt_qposadr[j])
        hinge = int(mj.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_HINGE)
        stiff = float(mj.jnt_stiffness[j])
        spring = float(mj.qpos_spring[qadr]) if stiff else 0.0
        exp.append(
            [mj.dof_armature[dof], mj.dof_damping[dof], mj.dof_frictionloss[dof], stiff, spring]
        )
        springref = float(_get(prim, "mjc:springref"))
        got = [float(_get(prim, name)) for name in JOINT_FIELDS]
        act.append([*got, math.radians(springref) if hinge else springref])
    return exp, act, missing


def _actuator_rows(stage, root: str, mj) -> tuple[list, list, list[str]]:
    """(expected, actual, mismatched targets): one MjcActuator per MuJoCo joint servo."""
    from pxr import Usd

    servos = {
        mj.joint(int(mj.actuator_trnid[a, 0])).name: a
        for a in range(mj.nu)
        if mj.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT
    }
    found: dict[str, object] = {}
    for prim in Usd.PrimRange(stage.GetPrimAtPath(root)):
        if prim.GetTypeName() == "MjcActuator":
            targets = prim.GetRelationship("mjc:target").GetTargets()
            found[str(targets[0].name) if len(targets) == 1 else str(prim.GetPath())] = prim
    names = {prim_name(n): n for n in servos}
    wrong = sorted(set(found) ^ set(names))
    exp, act = [], []
    for usd_name, prim in sorted(found.items()):
        if usd_name not in names:
            continue
        a = servos[names[usd_name]]
        ctrl = mj.actuator_ctrlrange[a] if mj.actuator_ctrllimited[a] else (0.0, 0.0)
        gains = [mj.actuator_gainprm[a, 0], *mj.actuator_biasprm[a, 1:3]]
        exp.append([*gains, *mj.actuator_forcerange[a], *ctrl])
        gain = [*_get(prim, "mjc:gainPrm", [0.0]), 0.0]
        bias = [*_get(prim, "mjc:biasPrm", [0.0]), 0.0, 0.0, 0.0]
        ranges = [float(_get(prim, f"mjc:{r}:{m}")) for r in RANGES for m in ("min", "max")]
        act.append([gain[0], bias[1], bias[2], *ranges])
    return exp, act, wrong


def mjc_findings(stage, top, mj) -> list[Finding]:
    """`usd.mjc.joints` and `usd.mjc.actuators` for the composed "mujoco" variant."""
    root = str(top.GetPath())
    jexp, jact, missing = _joint_rows(stage, root, mj)
    aexp, aact, wrong = _actuator_rows(stage, root, mj)
    jtol = REL * max(1.0, float(np.abs(jexp).max(initial=0)))
    atol = REL * max(1.0, float(np.abs(aexp).max(initial=0)))
    return [
        require(
            "usd.mjc.present",
            not missing and not wrong,
            f"MjcJointAPI on every MuJoCo hinge and slide joint (missing {missing}), one "
            f"MjcActuator per MuJoCo servo, targeting its joint (differ: {wrong})",
        ),
        compare(
            "usd.mjc.joints",
            "mjc: armature, damping, frictionloss, stiffness, springref vs MuJoCo",
            jexp,
            jact,
            jtol,
            "SI",
        ),
        compare(
            "usd.mjc.actuators",
            "MjcActuator gain, bias, force and control ranges vs MuJoCo's servos",
            aexp,
            aact,
            atol,
            "SI",
        ),
    ]
