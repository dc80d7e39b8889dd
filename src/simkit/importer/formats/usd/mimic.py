"""A USD mimic joint (a follower coupled to its leader) as the model's `Mimic` (the URDF
`<mimic joint multiplier offset>`) on the follower, q = multiplier q_leader + offset, so the
shared translation takes it as it takes a URDF's (translate/joints.py; convert.py drops a
mimic whose leader is no movable joint of the robot, with one report line, and imports the
follower independent).

Two schemas, neither registered with usd-core, so the applied schema is read from the prim's
`apiSchemas` metadata and the attributes by name, each at its schema's fallback where not
authored (converters author only what differs from it):

- Newton's `NewtonMimicAPI` (urdf-usd-converter writes a URDF's mimic as it, and
  mujoco-usd-converter an MJCF joint equality, with the polynomial's higher terms in
  `mjc:coef2..4`): `newton:mimicJoint` the leader, q = `newton:mimicCoef0` +
  `newton:mimicCoef1` q_leader (fallbacks 0 and 1), coef0 in degrees for an angular
  follower, in stage distance for a linear one; `newton:mimicEnabled` false: independent;
- PhysX's `PhysxMimicJointAPI:<rotX|rotY|rotZ>` (Isaac Sim's importers before Newton, and a
  simkit kit's revolute follower, emit/usd/mimic.py): `physxMimicJoint:<inst>:referenceJoint`
  the leader, q + gearing q_leader + offset = 0 (fallbacks 1 and 0), so multiplier -gearing
  and offset -offset; the offset in degrees or stage distance as Newton's (omni.physx turns
  it to radians for an angular follower), the gearing in follower units per leader unit.

Both are written in each joint's own UsdPhysics coordinate (body0 to body1), which the tree
keeps for a joint it turns round (tree.py flips the axis, not the coordinate), so the
coefficients carry over unchanged. A leader that is no joint prim is named by its path, which
names no joint, so the translation drops it as for a URDF; a relationship without exactly one
target, or a polynomial (nonzero `mjc:coef2..4`), is no linear mimic: one report line each,
the follower independent.
"""

from __future__ import annotations

import math

from simkit.importer.formats.usd import poses
from simkit.importer.read.model import At, Mimic

NEWTON = "NewtonMimicAPI"
PHYSX = "PhysxMimicJointAPI:"
#: MjcPhysics' higher polynomial terms beside Newton's linear ones (mujoco-usd-converter)
HIGHER = ("mjc:coef2", "mjc:coef3", "mjc:coef4")


def applied(prim) -> list[str]:
    """The prim's applied API schema tokens as authored (registered or not), in order."""
    ops = prim.GetMetadata("apiSchemas")
    return [str(t) for t in ops.ApplyOperations([])] if ops else []


def read(joint, names: dict[str, str], units: poses.Units) -> tuple[dict | None, str | None]:
    """({joint: leader name, multiplier, offset (rad or m)} or None, a report line or None)
    for the UsdPhysics joint prim `joint`; `names` maps joint prim paths to the joint names
    the reader gives them (stage.stage_names)."""
    schemas = applied(joint)
    if NEWTON in schemas:
        found = _newton(joint)
    else:
        instance = next((s[len(PHYSX) :] for s in schemas if s.startswith(PHYSX)), None)
        if instance is None:
            return None, None
        found = _physx(joint, f"physxMimicJoint:{instance}")
    if found is None:
        return None, None
    api, targets, coef0, coef1 = found
    if len(targets) != 1:
        return None, f"{api} names {len(targets)} leader joints, not one: imported as independent"
    if any(poses.get(joint, name) not in (None, 0.0) for name in HIGHER):
        why = "a polynomial coupling (MjcPhysics mjc:coef2..4), no linear mimic"
        return None, f"{api}: {why}: imported as independent"
    leader = joint.GetStage().GetPrimAtPath(targets[0])
    follower_unit = _unit(joint, units)
    ratio = follower_unit / _unit(leader, units) if leader else 1.0
    mimic = {
        "joint": names.get(str(targets[0]), str(targets[0])),
        "multiplier": coef1 * ratio,
        "offset": coef0 * follower_unit,
    }
    return mimic, None


def _newton(joint):
    """(api, leader targets, coef0, coef1) of NewtonMimicAPI; None where it is disabled."""
    if poses.get(joint, "newton:mimicEnabled") is False:
        return None
    rel = joint.GetRelationship("newton:mimicJoint")
    targets = rel.GetTargets() if rel else []
    coef0 = _or(poses.get(joint, "newton:mimicCoef0"), 0.0)
    return NEWTON, targets, coef0, _or(poses.get(joint, "newton:mimicCoef1"), 1.0)


def _physx(joint, base: str):
    """(api, leader targets, coef0, coef1) of a PhysxMimicJointAPI instance: q = -offset -
    gearing q_leader."""
    rel = joint.GetRelationship(f"{base}:referenceJoint")
    targets = rel.GetTargets() if rel else []
    gearing = _or(poses.get(joint, f"{base}:gearing"), 1.0)
    offset = _or(poses.get(joint, f"{base}:offset"), 0.0)
    return "PhysxMimicJointAPI", targets, -offset, -gearing


def _or(value, fallback: float) -> float:
    return fallback if value is None else float(value)


def _unit(joint, units: poses.Units) -> float:
    """SI per stage unit of the joint's coordinate: rad per degree for an angular joint,
    metres per unit for a prismatic one."""
    if joint.GetTypeName() == "PhysicsPrismaticJoint":
        return units.meters
    return math.radians(1.0)


def of(joint, names: dict[str, str], units: poses.Units, notes: list) -> Mimic | None:
    """The follower's `Mimic` where the joint prim is one (`read`); a mimic that is no linear
    one adds (where, why) to `notes`."""
    mimic, why = read(joint, names, units)
    if why is not None:
        notes.append((f"joint {joint.GetPath()}", why))
    if mimic is None:
        return None
    at = At("mimic")
    return Mimic(at, mimic["joint"], float(mimic["multiplier"]), float(mimic["offset"]))
