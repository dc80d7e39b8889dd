"""The USD asset structure as a user's tools see it: every layer the entry point composes has
a default prim, Z up and metres (and kilograms) per unit 1; every mesh has normals; Isaac Sim's
robot schema lists every link and joint; the thumbnail is a 256 x 256 PNG; the "none" physics
variant holds no physics. Read with pxr from the written files (the emitter is not consulted)."""

from __future__ import annotations

from pathlib import Path

from simkit.check.findings import Finding, require

#: the interface layer's variant set of physics flavours (docs/usd.md)
VARIANT_SET = "Physics"
THUMB_SIZE = 256


def applied(prim) -> list[str]:
    """The prim's composed apiSchemas as authored, registered with this pxr or not (Isaac
    Sim's robot schema is Isaac's plugin)."""
    op = prim.GetMetadata("apiSchemas")
    return [str(s) for s in op.ApplyOperations([])] if op else []


def layer_findings(stage) -> list[Finding]:
    """defaultPrim, upAxis Z, metersPerUnit 1 and kilogramsPerUnit 1 on every used layer."""
    from pxr import UsdGeom, UsdPhysics

    bad = []
    for layer in sorted(stage.GetUsedLayers(), key=lambda x: x.identifier):
        if layer.anonymous:  # the session layer
            continue
        meta = (
            layer.defaultPrim,
            layer.pseudoRoot.GetInfo(UsdGeom.Tokens.upAxis),
            layer.pseudoRoot.GetInfo(UsdGeom.Tokens.metersPerUnit),
            layer.pseudoRoot.GetInfo(UsdPhysics.Tokens.kilogramsPerUnit),
        )
        if not meta[0] or meta[1:] != ("Z", 1.0, 1.0):
            bad.append(f"{Path(layer.realPath).name} {meta}")
    return [
        require(
            "usd.layers",
            not bad,
            f"every composed layer has a defaultPrim, Z up, metres and kilograms per unit 1 "
            f"(not: {bad})",
        )
    ]


def normals_findings(stage) -> list[Finding]:
    """Every mesh, visual or collider, carries normals (SimReady VG.027)."""
    from pxr import Usd, UsdGeom

    missing = []
    for prim in Usd.PrimRange(stage.GetPseudoRoot(), Usd.TraverseInstanceProxies()):
        if prim.IsA(UsdGeom.Mesh):
            mesh = UsdGeom.Mesh(prim)
            primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar("normals")
            if not (primvar and primvar.HasValue()) and not mesh.GetNormalsAttr().HasValue():
                missing.append(str(prim.GetPath()))
    return [require("usd.normals", not missing, f"every mesh has normals (missing {missing[:5]})")]


def robot_schema_findings(stage, top, links: dict[str, str], joints: list[str]) -> list[Finding]:
    """IsaacRobotAPI on the default prim: robotLinks are the links, robotJoints the joints,
    in the written tree order, and isaac:robotType is set."""
    targets = {
        name: [str(t) for t in top.GetRelationship(f"isaac:physics:{name}").GetTargets()]
        for name in ("robotLinks", "robotJoints")
    }
    kind = top.GetAttribute("isaac:robotType")
    ok = "IsaacRobotAPI" in applied(top)
    return [
        require(
            "usd.robot_schema",
            ok
            and targets["robotLinks"] == list(links.values())
            and sorted(targets["robotJoints"]) == sorted(joints)
            and bool(kind and kind.Get()),
            f"IsaacRobotAPI with robotLinks = the {len(links)} links, robotJoints = the "
            f"{len(joints)} joints and isaac:robotType {kind.Get() if kind else None!r}",
        )
    ]


def thumbnail_findings(path: Path, check: str = "usd.thumbnail") -> list[Finding]:
    """`.thumbs/256x256/<layer file>.png` beside an interface layer, 256 x 256 pixels."""
    from PIL import Image

    thumb = path.parent / ".thumbs" / f"{THUMB_SIZE}x{THUMB_SIZE}" / f"{path.name}.png"
    size = None
    if thumb.is_file():
        with Image.open(thumb) as image:
            size = image.size
    return [
        require(
            check,
            size == (THUMB_SIZE, THUMB_SIZE),
            f"{thumb.relative_to(path.parent.parent).as_posix()}: a {THUMB_SIZE} x "
            f"{THUMB_SIZE} PNG (found {size})",
        )
    ]


def _resolved_text(path: Path) -> tuple[str, int] | None:
    """(the layer's text with each asset path it authors made absolute, how many), or None
    where the file does not open: two interface layers in different folders over the same
    payload files then read the same."""
    from pxr import Sdf

    layer = Sdf.Layer.FindOrOpen(str(path)) if path.is_file() else None
    if layer is None:
        return None
    text = layer.ExportToString()
    assets = sorted(set(layer.GetCompositionAssetDependencies()), key=len, reverse=True)
    for asset in assets:
        text = text.replace(f"@{asset}@", f"@{Path(layer.ComputeAbsolutePath(asset)).resolve()}@")
    return text, len(assets)


def asset_findings(entry: Path, asset: Path) -> list[Finding]:
    """The Isaac asset `usd/NAME/NAME.usda` (folder named as the file, SimReady RC.003) is the
    entry layer's twin: the same text over the same payload files, and its own thumbnail."""
    pair = _resolved_text(entry), _resolved_text(asset)
    same = None not in pair and pair[0] == pair[1]
    arcs = pair[1][1] if pair[1] else 0
    return [
        require(
            "usd.asset",
            same and asset.parent.name == asset.stem and arcs > 0,
            f"{asset.parent.name}/{asset.name}: the entry layer's twin over the same "
            f"{arcs} payload files, in a folder named as the file",
        ),
        *thumbnail_findings(asset, "usd.asset.thumbnail"),
    ]


def geometry_only_findings(stage) -> list[Finding]:
    """The "none" variant: no physics (no body, collider, joint or physics schema)."""
    from pxr import Usd, UsdGeom

    physics, meshes = [], 0
    for prim in Usd.PrimRange(stage.GetPseudoRoot()):
        meshes += prim.IsA(UsdGeom.Mesh)
        if str(prim.GetTypeName()).startswith(("Physics", "Mjc")) or any(
            s.startswith(("Physics", "Physx", "Isaac", "Mjc")) for s in applied(prim)
        ):
            physics.append(str(prim.GetPath()))
    return [
        require(
            "usd.none.geometry_only",
            not physics,  # a robot with no geometry at all has no mesh either
            f'variant "none": {meshes} meshes and no physics (physics on {physics[:3]})',
        )
    ]
