"""The geometry payload layers: `geometries.usd` (every mesh once: visual solids and convex
collision pieces, link frame, metres), `materials.usda` (one UsdPreviewSurface per spec
colour) and `instances.usda` (a link's visuals and colliders composed from those meshes and
the spec's collision primitives). Isaac Sim's robot asset structure keeps these apart so that
heavy mesh data loads once and is reviewed separately from the physics."""

from __future__ import annotations

from simkit.emit.usd.common import (
    collision_pieces,
    export,
    mesh,
    new_stage,
    piece_name,
    prim_name,
    primitive,
    r,
    reference,
)
from simkit.kitio.fmt import rounded
from simkit.model.robot import Robot

GEOMETRIES = "geometries"
INSTANCES = "instances"
LOOKS = "Looks"


def geometries_text(robot: Robot) -> str:
    """`/geometries/LINK/visual` and `/geometries/LINK/collision_NN` meshes."""
    layer, stage, _top = new_stage(robot, GEOMETRIES, "Scope")
    for link in robot.links:
        base = f"/{GEOMETRIES}/{prim_name(link.name)}"
        kind, pieces = collision_pieces(link)
        if link.solid is None and kind != "meshes":
            continue
        stage.DefinePrim(base, "Scope")
        if link.solid is not None:
            mesh(stage, f"{base}/visual", link.solid)
        if kind == "meshes":
            for i, piece in enumerate(pieces):
                mesh(stage, f"{base}/{piece_name(i)}", piece, shaded=False)
    return export(layer)


#: the material of a drawn link whose spec gives none (its colour: `Robot.material_rgba`)
UNASSIGNED = "unassigned"


def link_material(robot: Robot, link) -> str:
    """The material a link's visual mesh is bound to (every drawn mesh has one: SimReady
    VM.MAT.001)."""
    known = {name for name, _rgba in robot.materials}
    return link.material if link.material in known else UNASSIGNED


def looks(robot: Robot) -> list[tuple[str, tuple]]:
    """(material, RGBA) for `materials.usda`: the spec's colours, then UNASSIGNED if a drawn
    link needs it."""
    out = list(robot.materials)
    drawn = [link for link in robot.links if link.solid is not None]
    if any(link_material(robot, link) == UNASSIGNED for link in drawn):
        out.append((UNASSIGNED, robot.material_rgba(None)))
    return out


def materials_text(robot: Robot) -> str:
    """`/Looks/MATERIAL`: one UsdPreviewSurface material per spec colour."""
    from pxr import Gf, Sdf, UsdShade

    layer, stage, _top = new_stage(robot, LOOKS, "Scope")
    for name, rgba in looks(robot):
        path = f"/{LOOKS}/{prim_name(name)}"
        material = UsdShade.Material.Define(stage, path)
        shader = UsdShade.Shader.Define(stage, f"{path}/PreviewSurface")
        shader.CreateIdAttr("UsdPreviewSurface")
        shader.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(*r(rgba[:3])))
        shader.CreateInput("opacity", Sdf.ValueTypeNames.Float).Set(rounded(rgba[3]))
        shader.CreateInput("roughness", Sdf.ValueTypeNames.Float).Set(0.5)
        material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    return export(layer)


def instances_text(robot: Robot) -> str:
    """`/instances/LINK/visuals` (the link's solid, its display colour) and
    `/instances/LINK/collisions` (purpose guide: convex pieces or spec primitives)."""
    from pxr import Gf, UsdGeom

    layer, stage, _top = new_stage(robot, INSTANCES, "Scope")
    arcs: list[tuple[str, str]] = []
    for link in robot.links:
        name = prim_name(link.name)
        base = f"/{INSTANCES}/{name}"
        kind, pieces = collision_pieces(link)
        if link.solid is None and kind == "none":
            continue
        stage.DefinePrim(base, "Scope")
        if link.solid is not None:
            UsdGeom.Xform.Define(stage, f"{base}/visuals")
            geom = UsdGeom.Mesh.Define(stage, f"{base}/visuals/{name}")
            rgb = robot.material_rgba(link.material)[:3]
            geom.CreateDisplayColorAttr([Gf.Vec3f(*r(rgb))])
            arcs.append((f"{base}/visuals/{name}", f"/{GEOMETRIES}/{name}/visual"))
        if kind == "none":
            continue
        group = UsdGeom.Scope.Define(stage, f"{base}/collisions")
        group.CreatePurposeAttr(UsdGeom.Tokens.guide)
        for i, piece in enumerate(pieces):
            path = f"{base}/collisions/{piece_name(i)}"
            if kind == "primitives":
                primitive(stage, path, piece)
            else:
                UsdGeom.Mesh.Define(stage, path)
                arcs.append((path, f"/{GEOMETRIES}/{name}/{piece_name(i)}"))
    del stage
    for path, target in arcs:
        reference(layer, path, "./geometries.usd", target)
    return export(layer)
