"""`base.usda`: the robot's hierarchy without physics. `/NAME` (kind component) holds one Xform
per link at its pose at q = 0 in the root frame, its `visuals` and `collisions` referenced from
`instances.usda`, the spec's frames as Xforms, and `/NAME/Looks` referenced from
`materials.usda`; each visual mesh is bound to its link's material here, where the material
and the mesh meet."""

from __future__ import annotations

from simkit.emit.usd.common import collision_pieces, export, new_stage, place, prim_name, reference
from simkit.emit.usd.geometry import INSTANCES, LOOKS, link_material, looks
from simkit.model.kinematics import forward, rpy_matrix
from simkit.model.robot import Robot


def _frames(stage, base: str, robot: Robot, parent: str) -> None:
    from pxr import UsdGeom

    for frame in robot.frames:
        if frame.parent == parent:
            prim = UsdGeom.Xform.Define(stage, f"{base}/{prim_name(frame.name)}").GetPrim()
            place(prim, frame.xyz, rpy_matrix(frame.rpy))


def base_text(robot: Robot) -> str:
    """The `base.usda` text."""
    from pxr import Kind, Usd, UsdGeom, UsdShade

    root = prim_name(robot.name)
    layer, stage, top = new_stage(robot, root)
    Usd.ModelAPI(top).SetKind(Kind.Tokens.component)
    arcs: list[tuple[str, str, str]] = []
    _frames(stage, f"/{root}", robot, robot.root)
    if looks(robot):
        stage.DefinePrim(f"/{root}/{LOOKS}", "Scope")
        arcs.append((f"/{root}/{LOOKS}", "./materials.usda", ""))
    poses = forward(robot)
    for link in robot.links:
        name = prim_name(link.name)
        base = f"/{root}/{name}"
        pose = poses[link.name]
        place(UsdGeom.Xform.Define(stage, base).GetPrim(), pose[:3, 3], pose[:3, :3])
        if link.solid is not None:
            UsdGeom.Xform.Define(stage, f"{base}/visuals")
            arcs.append((f"{base}/visuals", "./instances.usda", f"/{INSTANCES}/{name}/visuals"))
            over = stage.OverridePrim(f"{base}/visuals/{name}")
            UsdShade.MaterialBindingAPI.Apply(over)
            rel = over.CreateRelationship(UsdShade.Tokens.materialBinding, custom=False)
            rel.SetTargets([f"/{root}/{LOOKS}/{prim_name(link_material(robot, link))}"])
        if collision_pieces(link)[0] != "none":
            UsdGeom.Scope.Define(stage, f"{base}/collisions")
            target = f"/{INSTANCES}/{name}/collisions"
            arcs.append((f"{base}/collisions", "./instances.usda", target))
        _frames(stage, base, robot, link.name)
    del stage
    for path, asset, target in arcs:
        reference(layer, path, asset, target)
    return export(layer)
