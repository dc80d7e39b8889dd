"""A USD joint's effort and speed limits (the URDF `<limit effort velocity>`), read apart from
its position range (tree.py).

Effort (N m for a revolute joint, N for a prismatic one): `simkit:effortLimit` where the joint
carries it (a simkit kit's USD writes the joint's own limit there, since UsdPhysics has no
field for it; authored, it decides, 0 meaning none), else its drive's `maxForce` (the force
a simulator lets the drive apply, the best a converter's USD offers). Both are in the stage's
units: kilograms times metres (squared for a revolute joint) per unit. Where the joint carries
both, the drive's `maxForce` is the servo's force (`servo_force`), kept apart from the limit.

Speed (deg/s or m/s): PhysX's `maxJointVelocity` (per axis, else on PhysxJointAPI) or Newton's
`velocityLimit`. A value that is not finite and positive (USD writes +-inf or FLT_MAX for
none) is no limit.
"""

from __future__ import annotations

from simkit.importer.formats.usd import poses

#: the joint's effort limit in a simkit kit's USD (emit/usd/physics.py writes it)
EFFORT_LIMIT = "simkit:effortLimit"
#: |value| at or above which a limit means none
UNBOUNDED = 1e30


def _finite(value) -> float | None:
    if value is None or not 0 < float(value) < UNBOUNDED:
        return None
    return float(value)


def effort(joint, kind: str, units: poses.Units) -> float | None:
    """The joint's effort limit (N m or N; `kind` revolute or prismatic), None without one."""
    drive = "angular" if kind == "revolute" else "linear"
    own = poses.get(joint, EFFORT_LIMIT)
    force = _finite(own if own is not None else poses.get(joint, f"drive:{drive}:physics:maxForce"))
    if force is None:
        return None
    return force * (units.kilograms * units.meters * (1 if kind == "prismatic" else units.meters))


def servo_force(joint, kind: str, units: poses.Units) -> float | None:
    """The drive's `maxForce` (N m or N) of a joint that carries its own effort limit too: the
    servo's force apart from the limit (a simkit kit's USD), which the spec keeps as
    `drive_peak_torque_at_joint`; None otherwise (the maxForce is then the effort)."""
    if poses.get(joint, EFFORT_LIMIT) is None:
        return None
    drive = "angular" if kind == "revolute" else "linear"
    force = _finite(poses.get(joint, f"drive:{drive}:physics:maxForce"))
    if force is None:
        return None
    return force * (units.kilograms * units.meters * (1 if kind == "prismatic" else units.meters))


def velocity(joint, kind: str) -> float | None:
    """The joint's speed limit in the stage's units (deg/s or distance/s), None without one."""
    drive = "angular" if kind == "revolute" else "linear"
    for name in (
        f"physxJointAxis:{drive}:maxJointVelocity",
        "physxJoint:maxJointVelocity",
        "newton:velocityLimit",
    ):
        speed = poses.get(joint, name)
        if speed is not None:
            return _finite(speed)
    return None
