"""The composed stage of a USD robot and its articulation (bodies and joints), as usd-core
composes it: the `Physics` variant the user names (`--variant`) or the file's default, every
payload loaded, then the one articulation found.

The articulation: the prims with `PhysicsArticulationRootAPI`. None, and no joint between
rigid bodies: refused ("no articulation"); several: refused ("several robots"). A stage with
joints but no articulation root is read as one articulation (a report line says so). The
bodies are the rigid bodies the joints connect to the root body, found from the root prim
(a rigid body, a joint's body1, or the body no joint hangs from under it).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from simkit.errors import SpecError

#: the variant set whose choice the user names with `--variant`
VARIANT_SET = "Physics"


@dataclass
class Articulation:
    """The robot on the stage: its root prim, bodies (prim paths, sorted) and joints
    (UsdPhysics.Joint prims, in the stage's order as authored) that touch them."""

    stage: object
    root_prim: object
    bodies: list[str] = field(default_factory=list)
    joints: list[object] = field(default_factory=list)
    variant: str | None = None
    notes: list[str] = field(default_factory=list)
    #: further root bodies, each bolted to the world like the first (several articulations
    #: of one robot: urdf-usd-converter writes one per child of a massless root link)
    more_roots: list[str] = field(default_factory=list)
    #: (kind, prim paths) left out as the scene's, not the robot's: "links" (rigid bodies not
    #: joined to it), "joints" (joints touching none of its bodies)
    apart: dict[str, list[str]] = field(default_factory=dict)


def open_stage(path: Path, root_layer, variant: str | None):
    """(stage, the variant read or None): the stage over `root_layer` (confine.py holds
    every layer it composes open), payloads loaded, `variant` selected on every prim
    carrying the `Physics` set (one line when no prim offers it)."""
    from pxr import Usd

    stage = Usd.Stage.Open(root_layer, Usd.Stage.LoadAll)
    prims = [p for p in stage.Traverse() if p.GetVariantSets().HasVariantSet(VARIANT_SET)]
    if variant is None:
        chosen = {p.GetVariantSet(VARIANT_SET).GetVariantSelection() for p in prims}
        return stage, (sorted(chosen)[0] if len(chosen) == 1 and "" not in chosen else None)
    offered = sorted({n for p in prims for n in p.GetVariantSet(VARIANT_SET).GetVariantNames()})
    if variant not in offered:
        have = ", ".join(offered) if offered else "none: the stage has no Physics variant set"
        raise SpecError(str(path), None, "--variant", f"no Physics variant '{variant}' ({have})")
    with Usd.EditContext(stage, stage.GetSessionLayer()):
        for prim in prims:
            if variant in prim.GetVariantSet(VARIANT_SET).GetVariantNames():
                prim.GetVariantSet(VARIANT_SET).SetVariantSelection(variant)
    return stage, variant


def articulation(path: Path, stage) -> Articulation:
    """The one articulation on `stage` (module docstring); one line for none or several."""
    from pxr import Usd, UsdPhysics

    every = Usd.TraverseInstanceProxies(Usd.PrimAllPrimsPredicate)
    prims = list(Usd.PrimRange(stage.GetPseudoRoot(), every))
    bodies = {str(p.GetPath()) for p in prims if p.HasAPI(UsdPhysics.RigidBodyAPI)}
    joints = [p for p in prims if p.IsA(UsdPhysics.Joint) and p.IsActive()]
    roots = [p for p in prims if p.HasAPI(UsdPhysics.ArticulationRootAPI)]
    linking = [j for j in joints if {t for t in _ends(j) if t} & bodies]
    graph = _graph(linking, bodies)
    held = _bolted(roots, graph, bodies, linking) if len(roots) > 1 else []
    if len(roots) > 1 and not held:
        names = ", ".join(str(p.GetPath()) for p in roots[:4])
        raise SpecError(
            str(path), None, f"prim {roots[1].GetPath()}",
            f"several robots (articulation roots: {names}): import one per file",
        )  # fmt: skip
    if not bodies or not linking:
        raise SpecError(
            str(path), None, "stage",
            "no articulation (no rigid bodies joined by UsdPhysics joints): nothing to import",
        )  # fmt: skip
    notes = []
    if not roots:
        notes.append("no PhysicsArticulationRootAPI: the stage's jointed bodies read as one robot")
    root = held[0] if held else _root_body(roots[0] if roots else None, graph, bodies, linking)
    found = set().union(*(_connected(r, graph) for r in held or [root]))
    if not roots:  # without a root, jointed bodies apart from the robot are another robot
        rest = bodies - found - {b for b in bodies if not graph.get(b)}
        if rest:
            raise SpecError(
                str(path), None, f"prim {sorted(rest)[0]}",
                "several robots (jointed bodies not connected to each other): import one per file",
            )  # fmt: skip
    apart = bodies - found
    if apart:
        notes.append(
            f"not imported: {len(apart)} rigid bodies not joined to the robot (first "
            f"{sorted(apart)[0]}): objects of the scene, not the robot"
        )
    touching = [j for j in linking if {t for t in _ends(j) if t} & found]
    out = Articulation(stage, stage.GetPrimAtPath(root), sorted(found), touching, notes=notes)
    out.more_roots = held[1:]
    away = [str(j.GetPath()) for j in joints if not {t for t in _ends(j) if t} & found]
    out.apart = {"links": sorted(apart), "joints": sorted(away)}
    return out


def _bolted(roots, graph, bodies: set[str], joints: list) -> list[str]:
    """The root bodies of several articulations that are one robot: each held to the world
    by a fixed joint from the same prim that is no body and holds them all (the robot's own
    prim); [] when they are not (several robots)."""
    from pxr import UsdPhysics

    out, hubs = [], set()
    for prim in roots:
        body = _root_body(prim, graph, bodies, joints)
        fixed = [
            j for j in joints
            if j.IsA(UsdPhysics.FixedJoint) and _ends(j)[1] == body and _ends(j)[0] not in bodies
        ]  # fmt: skip
        if not fixed:
            return []
        hubs.add(_ends(fixed[0])[0])
        out.append(body)
    hub = next(iter(hubs)) if len(hubs) == 1 else None
    inside = hub is not None and all(b.startswith(f"{hub}/") for b in out)
    return sorted(set(out)) if inside else []


def _ends(joint) -> tuple[str | None, str | None]:
    """(body0, body1) prim paths of a joint (None: not set)."""
    from pxr import UsdPhysics

    api = UsdPhysics.Joint(joint)
    out = []
    for rel in (api.GetBody0Rel(), api.GetBody1Rel()):
        targets = rel.GetTargets() if rel else []
        out.append(str(targets[0]) if targets else None)
    return out[0], out[1]


def ends(joint) -> tuple[str | None, str | None]:
    """(body0, body1) prim paths of a joint prim (None: not set)."""
    return _ends(joint)


def _graph(joints: list, bodies: set[str]) -> dict[str, set[str]]:
    """Body -> the bodies a joint joins it to."""
    graph: dict[str, set[str]] = {b: set() for b in bodies}
    for joint in joints:
        a, b = _ends(joint)
        if a in bodies and b in bodies:
            graph[a].add(b)
            graph[b].add(a)
    return graph


def _connected(root: str, graph: dict[str, set[str]]) -> set[str]:
    found, todo = {root}, [root]
    while todo:
        for other in sorted(graph.get(todo.pop(), ())):
            if other not in found:
                found.add(other)
                todo.append(other)
    return found


def _root_body(root_prim, graph: dict, bodies: set[str], joints: list) -> str:
    """The root body: the articulation root itself when it is a body, a joint's body1 when
    it is a joint, else the body a world joint (no body0) holds, else the body under the
    root prim that no joint's body1 names (the first such, by path)."""
    from pxr import UsdPhysics

    if root_prim is not None:
        at = str(root_prim.GetPath())
        if at in bodies:
            return at
        if root_prim.IsA(UsdPhysics.Joint):
            body = _ends(root_prim)[1]
            if body in bodies:
                return body
    under = sorted(
        b for b in bodies if root_prim is None or b.startswith(str(root_prim.GetPath()) + "/")
    ) or sorted(bodies)
    for joint in sorted(joints, key=lambda j: str(j.GetPath())):
        a, b = _ends(joint)
        if a not in bodies and b in under:
            return b
    children = {_ends(j)[1] for j in joints if _ends(j)[0] in bodies}
    free = [b for b in under if b not in children and graph.get(b)]
    return (free or under)[0]


def unique_names(stage, paths: list[str]) -> dict[str, str]:
    """Prim path -> its name: its `displayName` where authored (the source's own name, which
    converters keep there when it is no USD identifier, `0` for a prim `tn__0_`), else the
    prim's; made unique in path order (`NAME_1`, `NAME_2`...)."""
    out, taken = {}, set()
    for path in sorted(paths):
        prim = stage.GetPrimAtPath(path)
        shown = prim.GetDisplayName() if prim else ""
        want = shown or path.rsplit("/", 1)[-1] or "root"
        name, n = want, 1
        while name in taken:
            name, n = f"{want}_{n}", n + 1
        taken.add(name)
        out[path] = name
    return out


def stage_names(stage) -> dict[str, dict[str, str]]:
    """{"links": rigid body path -> name, "joints": joint path -> name} over the whole stage
    (unique_names): a robot's names do not depend on the scene around it being left out,
    and are those the source check (check/source/usd/), which reads the whole stage, gives."""
    from pxr import Usd, UsdPhysics

    every = Usd.TraverseInstanceProxies(Usd.PrimAllPrimsPredicate)
    prims = list(Usd.PrimRange(stage.GetPseudoRoot(), every))
    bodies = [str(p.GetPath()) for p in prims if p.HasAPI(UsdPhysics.RigidBodyAPI)]
    joints = [str(p.GetPath()) for p in prims if p.IsA(UsdPhysics.Joint) and p.IsActive()]
    return {"links": unique_names(stage, bodies), "joints": unique_names(stage, joints)}
