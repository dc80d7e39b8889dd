"""The source's joint damping (N m s/rad or N s/m), friction loss (N m or N) and armature
(kg m^2 or kg), read from the composed stage's attributes themselves: usd-core's UsdPhysics
parser (`LoadUsdPhysicsFromRange`) has no field for them, UsdPhysics no schema.

The rule the import states (importer/formats/usd/dynamics.py), written again here so the
proof does not lean on the reader it checks: MjcPhysics `mjc:damping`, `mjc:frictionloss`,
`mjc:armature` on the joint in the stage with the import's variant, PhysX's
`physxJointAxis:angular|linear:armature` (else `physxJoint:armature`) for the armature, and
what that stage lacks from the stage composed with each other `Physics` variant (by name,
the first that has it): a variant set's variants are one robot for different simulators.
An armature of 0 is none (the kit estimates one).
"""

from __future__ import annotations

import numpy as np

MJC = {"damping": "mjc:damping", "friction": "mjc:frictionloss", "armature": "mjc:armature"}


def _value(prim, name: str) -> float | None:
    attr = prim.GetAttribute(name) if prim else None
    value = attr.Get() if attr else None
    if value is None:
        return None
    if str(attr.GetTypeName()) in ("float", "half"):
        return float(str(np.float32(value)))
    return float(value)


def others(stage, variant: str | None) -> list:
    """The stage composed with each other `Physics` variant (sorted by name)."""
    from pxr import Sdf, Usd

    prims = [p for p in stage.Traverse() if p.GetVariantSets().HasVariantSet("Physics")]
    names = sorted({n for p in prims for n in p.GetVariantSet("Physics").GetVariantNames()})
    picked = {p.GetVariantSet("Physics").GetVariantSelection() for p in prims}
    out = []
    for name in names:
        if name == variant or {name} == picked:
            continue
        other = Usd.Stage.Open(stage.GetRootLayer(), Sdf.Layer.CreateAnonymous(), Usd.Stage.LoadAll)
        with Usd.EditContext(other, other.GetSessionLayer()):
            for prim in prims:
                sets = other.GetPrimAtPath(prim.GetPath()).GetVariantSets()
                if name in sets.GetVariantSet("Physics").GetVariantNames():
                    sets.GetVariantSet("Physics").SetVariantSelection(name)
        out.append(other)
    return out


def of_joint(prim, label: str, kilograms: float, meters: float, more: list) -> dict[str, float]:
    """{damping, friction, armature} (SI) the source gives the joint, where it gives them."""
    axis = "angular" if label == "revolute" else "linear"
    found = {key: _value(prim, name) for key, name in MJC.items()}
    for name in (f"physxJointAxis:{axis}:armature", "physxJoint:armature"):
        found["armature"] = (
            found["armature"] if found["armature"] is not None else _value(prim, name)
        )
    for stage in more:
        there = stage.GetPrimAtPath(prim.GetPath())
        for key, name in MJC.items():
            if found[key] is None:
                found[key] = _value(there, name)
    lever = meters if label == "revolute" else 1.0
    unit = {
        "damping": kilograms * lever**2,
        "armature": kilograms * lever**2,
        "friction": kilograms * meters * lever,
    }
    out = {k: v * unit[k] for k, v in found.items() if v is not None and v >= 0.0}
    if not out.get("armature"):
        out.pop("armature", None)
    return out
