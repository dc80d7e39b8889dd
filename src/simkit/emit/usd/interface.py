"""The interface layer of Isaac Sim's robot asset structure, written twice over one set of
payloads: `usd/NAME/NAME.usda` (the Isaac asset) and `usd/NAME.usda` (the kit's entry point).
Its default prim `/NAME` (kind component) references `payloads/base.usda` and holds the variant
set `Physics`: "none" (geometry only), "physics" (UsdPhysics: `physics.usda`, for any USD
physics reader, Newton included), "physx" (the default: `physics.usda` with `physx.usda` on
top, for Isaac Sim) and "mujoco" (`physics.usda` with `mujoco.usda`, MuJoCo's MjcPhysics
schemas, on top). The root layer's customLayerData carries the SimReady provenance
(`SimReady_Metadata`, rule SR.004) and simkit's own."""

from __future__ import annotations

import numpy as np

from simkit.emit.ros2 import DEFAULT_MAINTAINER, default_license
from simkit.emit.usd.common import export, new_stage, prim_name, r
from simkit.kitio.fmt import rounded
from simkit.model.kinematics import forward
from simkit.model.robot import Robot

VARIANT_SET = "Physics"
#: variant -> payload layers, strongest first
VARIANTS = {
    "none": (),
    "physics": ("physics.usda",),
    "physx": ("physx.usda", "physics.usda"),
    "mujoco": ("mujoco.usda", "physics.usda"),
}
DEFAULT_VARIANT = "physx"
#: Wikidata's "robot" (Q11012): the SimReady category code of every kit
QCODE = "Q11012"
#: a kit is a pure function of its spec: no clock is read, so no generation date is recorded
UNDATED = "not recorded: the same spec always gives the same bytes"


def extents(robot: Robot) -> list[float]:
    """Size (m) of the visual solids' axis-aligned box in the root frame at q = 0."""
    poses = forward(robot)
    points = [
        link.solid.vertices @ poses[link.name][:3, :3].T + poses[link.name][:3, 3]
        for link in robot.links
        if link.solid is not None
    ]
    if not points:
        return [0.0, 0.0, 0.0]
    stacked = np.concatenate(points)
    return r(stacked.max(axis=0) - stacked.min(axis=0))


def metadata(robot: Robot) -> dict:
    """customLayerData: the SimReady_Metadata fields and simkit's provenance."""
    from pxr import Gf

    return {
        "SimReady_Metadata": {
            "author": (robot.maintainer or DEFAULT_MAINTAINER)[0],
            "asset_name": robot.name,
            "asset_type": "robot",
            "asset_license": robot.license or default_license(robot),
            "category": "robot",
            "source_file": robot.spec_file,
            "usd_date_generated": UNDATED,
            "qcode": QCODE,
            "rigid_body_count": len(robot.links),
            "asset_extents": Gf.Vec3f(*extents(robot)),
            "mass": rounded(robot.total_mass),
        },
        # who made the asset from what; versions and the spec's hash are robot.json's
        # provenance, so that a rebuild by a newer simkit changes no USD file
        "simkit": {"generator": "simkit", "spec": robot.spec_file},
    }


def interface_text(robot: Robot, payloads: str = "./payloads") -> str:
    """An interface layer's text; `payloads` is the payload folder relative to the layer."""
    from pxr import Kind, Sdf, Usd

    name = prim_name(robot.name)
    layer, stage, top = new_stage(robot, name)
    Usd.ModelAPI(top).SetKind(Kind.Tokens.component)
    layer.customLayerData = metadata(robot)
    variants = top.GetVariantSets().AddVariantSet(VARIANT_SET)
    for variant in VARIANTS:
        variants.AddVariant(variant)
    variants.SetVariantSelection(DEFAULT_VARIANT)
    del stage
    spec = layer.GetPrimAtPath(f"/{name}")
    spec.referenceList.Prepend(Sdf.Reference(f"{payloads}/base.usda"))
    for variant, files in VARIANTS.items():
        arcs = spec.variantSets[VARIANT_SET].variants[variant].primSpec.payloadList
        arcs.prependedItems = [Sdf.Payload(f"{payloads}/{file}") for file in files]
    return export(layer)
