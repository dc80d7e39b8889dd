"""A USD joint's passive dynamics: damping (N m s/rad or N s/m), friction loss (N m or N) and
rotor inertia, armature (kg m^2 or kg), the URDF `<dynamics damping friction>` and the spec's
`armature`.

UsdPhysics has no field for them. MjcPhysics' `MjcJointAPI` has all three (`mjc:damping`,
`mjc:frictionloss`, `mjc:armature`: MuJoCo's joint attributes, which mujoco-usd-converter and
a simkit kit's `mujoco` variant write); PhysX has the armature only
(`physxJointAxis:<axis>:armature`, else `physxJoint:armature`; its friction is a unitless
coefficient or efforts of another model, not read). Values are in the stage's units:
kilograms times metres (squared for a revolute joint) per unit, per second for damping.

Which layer decides: the composed stage with the variant the import reads. What it lacks is
taken from the stage composed with each other variant of its `Physics` set (by name, the
first that has it), because a variant set's variants are one robot written for different
simulators: a joint's damping, friction and rotor inertia belong to the robot, not to the
simulator, and the MjcPhysics variant is the only one able to say them. The other choice,
writing `mjc:` attributes into a kit's PhysX variant too, would put another simulator's
schema there and would not help a converter's USD. Composing another variant reads no new
file: confine.py has already checked and opened every layer every variant names.

An armature of 0 is no armature (what a converter writes for none): the import's estimate
(fixups/rotors.py) stands, since the kit's servo needs rotor inertia to stay stable.
"""

from __future__ import annotations

from simkit.importer.formats.usd import poses
from simkit.importer.formats.usd.stage import VARIANT_SET
from simkit.importer.read.model import At, Dynamics

#: spec key -> MjcPhysics attribute
MJC = {"damping": "mjc:damping", "friction": "mjc:frictionloss", "armature": "mjc:armature"}


def variant_stages(stage, chosen: str | None) -> list:
    """The stage composed with each other variant of its `Physics` set (sorted by name), over
    the same layers (no new file read); [] when the stage has no such set."""
    from pxr import Sdf, Usd

    prims = [p for p in stage.Traverse() if p.GetVariantSets().HasVariantSet(VARIANT_SET)]
    picked = {p.GetVariantSet(VARIANT_SET).GetVariantSelection() for p in prims}
    names = sorted({n for p in prims for n in p.GetVariantSet(VARIANT_SET).GetVariantNames()})
    out = []
    for name in names:
        if name == chosen or {name} == picked:
            continue
        other = Usd.Stage.Open(stage.GetRootLayer(), Sdf.Layer.CreateAnonymous(), Usd.Stage.LoadAll)
        with Usd.EditContext(other, other.GetSessionLayer()):
            for prim in prims:
                here = other.GetPrimAtPath(prim.GetPath())
                if here and name in here.GetVariantSet(VARIANT_SET).GetVariantNames():
                    here.GetVariantSet(VARIANT_SET).SetVariantSelection(name)
        out.append(other)
    return out


def of_joint(joint, kind: str, units: poses.Units, others: list) -> dict[str, float]:
    """{damping, friction, armature} the USD gives the joint (SI; module docstring), each
    only where authored (an armature only where positive)."""
    axis = "angular" if kind == "revolute" else "linear"
    own = {key: poses.get(joint, name) for key, name in MJC.items()}
    if own["armature"] is None:
        own["armature"] = poses.get(joint, f"physxJointAxis:{axis}:armature")
    if own["armature"] is None:
        own["armature"] = poses.get(joint, "physxJoint:armature")
    for other in others:
        prim = other.GetPrimAtPath(joint.GetPath())
        for key, name in MJC.items():
            if prim and own[key] is None:
                own[key] = poses.get(prim, name)
    lever = units.meters if kind == "revolute" else 1.0
    mass = units.kilograms * lever**2  # kg m^2 (kg): armature, damping per rad (per m)
    scale = {"damping": mass, "armature": mass, "friction": units.kilograms * units.meters * lever}
    out = {}
    for key, value in sorted(own.items()):
        if value is None or not float(value) >= 0.0:
            continue
        if key == "armature" and not float(value) > 0.0:
            continue
        out[key] = float(value) * scale[key]
    return out


def model(found: dict[str, float]) -> Dynamics | None:
    """The joint's `Dynamics` (damping N m s/rad or N s/m, friction N m or N), as the shared
    translation reads it; None where both are 0 or not given."""
    if not (found.get("damping") or found.get("friction")):
        return None
    damping, friction = (float(found.get(k, 0.0)) for k in ("damping", "friction"))
    return Dynamics(At("dynamics"), damping, friction)
