"""Mesh links as STEP solids (mm): one faceted solid per separate piece of the derived mesh.

Pieces that face inward (cavities) become inner shells of the smallest outer piece whose box
holds them; a link of several solids is a compound. No Boolean fuse: the mesh is already
manifold3d's union, so its pieces are disjoint or only touch, and fusing faceted solids of
thousands of faces took minutes per link and could lose volume (a 2-piece knee of 3,478
triangles: 85 s and a third of its volume). A cavity as a solid of its own has a negative
volume that a STEP reader drops.

Issue 32, class 4: one link must not fail the robot. A mesh whose weld is not plainly a
closed manifold (an edge not on exactly two triangles, a needle, a flat piece) can give a
solid that fails BRepCheck (the union of two overlapping hulls leaves slivers at their
seam) or loses volume (a thin plate welded at 1e-2 mm). Each piece of such a mesh is tried
in turn as its weld and repairs (facets.py), coarser copies (manifold3d `simplify`, up to
`COARSER_M[-1]`) and its convex hull; the first whole candidate that passes BRepCheck and
holds the piece's volume within `VOLUME_SLACK` is kept. Where none does, the link has no
STEP solid and `mesh_shape` says why (robot.json and the kit README list it). A plain mesh
is faceted as before, unvalidated: BRepCheck costs about 0.3 s per 1,400 faces.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from simkit.derive.facets import MM, WELD_MM, faceted, merged, solid_volume
from simkit.model.robot import Mesh

if TYPE_CHECKING:
    from OCP.TopoDS import TopoDS_Shape

#: m^3: a piece holding less is flat (a sliver left by a Boolean), no solid at all
ZERO_VOLUME_M3 = 1e-15
#: relative: how far a candidate's volume may be off its piece's (a tenth of the check's 1 %)
VOLUME_SLACK = 0.001
#: mm: a triangle lower than this may lose its face in Open CASCADE (a UR arm's CAD meshes
#: with triangles 3.2e-5 mm high make whole shells; seams of 2e-8 mm do not)
NEEDLE_MM = 1e-5
#: m: the `simplify` tolerances of the coarser copies, finest first
COARSER_M = (1e-7, 1e-6, 1e-5)


def components(faces: np.ndarray) -> list[np.ndarray]:
    """The faces of each vertex-connected piece of a mesh (by vertex index), in first-face
    order: manifold3d keeps solids that only touch as separate shells."""
    parent = list(range(int(faces.max()) + 1))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b, c in faces.tolist():
        for other in (b, c):
            ra, rb = root(a), root(other)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    labels = np.array([root(int(f[0])) for f in faces])
    return [faces[labels == label] for label in dict.fromkeys(labels.tolist())]


def signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Signed volume of a closed triangle mesh (units^3; < 0 for an inward-facing piece)."""
    tri = vertices[faces]
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6)


def plain(mesh: Mesh) -> bool:
    """True when the mesh welded at `WELD_MM` uses each directed edge once and its reverse
    once (a closed, consistently wound manifold by index), has no needle (every triangle at
    least `NEEDLE_MM` high: Open CASCADE drops lower faces) and no flat piece: its faceted
    shell is whole as it stands. Cheap (numpy), so only other meshes pay for validation."""
    faces = np.asarray(mesh.faces, dtype=np.int64)
    points = np.asarray(mesh.vertices, dtype=float) * MM
    nodes, tris = merged(points, faces, WELD_MM)
    if not len(tris):
        return False
    edges = tris[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)
    code, back = edges[:, 0] * len(nodes) + edges[:, 1], edges[:, 1] * len(nodes) + edges[:, 0]
    if len(np.unique(code)) != len(code) or not np.isin(back, code).all():
        return False
    corner = nodes[tris]
    sides = np.linalg.norm(corner - np.roll(corner, 1, axis=1), axis=2).max(axis=1)
    twice_area = np.linalg.norm(
        np.cross(corner[:, 1] - corner[:, 0], corner[:, 2] - corner[:, 0]), axis=1
    )
    if (twice_area < NEEDLE_MM * np.maximum(sides, 1e-300)).any():
        return False
    vertices = np.asarray(mesh.vertices, dtype=float)
    return all(abs(signed_volume(vertices, p)) > ZERO_VOLUME_M3 for p in components(faces))


#: Plan = the candidate kept for each piece of a checked mesh (0: the weld or its repair,
#: then `COARSER_M` in order, then the hull), None for a link left out of the STEP
Plan = tuple[int, ...] | None


def mesh_solid(mesh: Mesh) -> TopoDS_Shape | None:
    """`mesh_shape` without its reason."""
    return mesh_shape(mesh)[0]


def mesh_plan(mesh: Mesh) -> tuple[Plan, str]:
    """The candidates a checked mesh keeps (or None and why none is sound); () for a plain
    mesh, which is faceted as it stands. Open CASCADE runs only for a mesh that is not plain."""
    if plain(mesh):
        return (), ""
    shape, why, plan = _search(mesh, None)
    return (plan, "") if shape is not None else (None, why)


def mesh_shape(mesh: Mesh, plan: Plan | None = None) -> tuple[TopoDS_Shape | None, str]:
    """A closed mesh (m) as solids (mm), or None and why it gives no valid solid. `plan`
    (from `mesh_plan`, which checks) builds the kept candidates without checking again."""
    if plan == ():
        return _assemble(mesh, False, None)[:2]
    return _search(mesh, plan)[:2]


def _search(mesh: Mesh, plan: Plan) -> tuple[TopoDS_Shape | None, str, Plan]:
    check = not plain(mesh)
    return _assemble(mesh, check, plan)


def _assemble(mesh: Mesh, check: bool, plan: Plan) -> tuple[TopoDS_Shape | None, str, Plan]:
    """The pieces as solids with their cavities as inner shells (module doc); `check`: each
    piece is a sound candidate (or the one `plan` names), flat pieces dropped."""
    from OCP.BRep import BRep_Builder
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Compound

    vertices = np.asarray(mesh.vertices, dtype=float)
    parts = components(np.asarray(mesh.faces, dtype=int))
    volumes = [signed_volume(vertices, part) for part in parts]
    if check:  # a flat piece (a Boolean's sliver) holds nothing: no solid of its own
        keep = [i for i, v in enumerate(volumes) if abs(v) > ZERO_VOLUME_M3]
        parts, volumes = [parts[i] for i in keep], [volumes[i] for i in keep]
    outer = [i for i, v in enumerate(volumes) if v >= 0]
    made = [
        _piece(Mesh.of(vertices, parts[i]), volumes[i], check, plan[i] if plan else None)
        for i in range(len(parts))
    ]
    broken = [i for i, (solid, _k) in enumerate(made) if solid is None]
    if broken or not outer:
        return None, _why(len(parts[broken[0]]) if broken else 0), None
    pieces = {i: made[i][0] for i in outer}
    builder = BRep_Builder()
    for i, volume in enumerate(volumes):
        host = _host(vertices, parts, outer, volumes, i) if volume < 0 else None
        if host is None and volume < 0:
            pieces[i] = made[i][0]  # nothing holds it
        elif host is not None:
            builder.Add(pieces[host], TopExp_Explorer(made[i][0], TopAbs_SHELL).Current())
    solids = [pieces[i] for i in sorted(pieces)]
    if check and plan is None and not all(_valid(s) for s in solids):
        return None, _why(0), None
    kept = tuple(k for _s, k in made)
    if len(solids) == 1:
        return solids[0], "", kept
    compound = TopoDS_Compound()
    builder.MakeCompound(compound)
    for solid in solids:
        builder.Add(compound, solid)
    return compound, "", kept


def _why(triangles: int) -> str:
    piece = f"a piece of {triangles} triangles" if triangles else "its solid"
    return (
        f"no valid STEP solid: {piece} stays open or fails BRepCheck after a re-weld, coarser "
        f"meshes (to {COARSER_M[-1]:g} m) and its convex hull"
    )


def _host(vertices, parts, outer: list[int], volumes, cavity: int) -> int | None:
    """The smallest outer piece whose bounding box holds the cavity's, or None."""
    low, high = vertices[parts[cavity]].min(axis=(0, 1)), vertices[parts[cavity]].max(axis=(0, 1))
    holders = [
        i
        for i in outer
        if np.all(vertices[parts[i]].min(axis=(0, 1)) <= low)
        and np.all(vertices[parts[i]].max(axis=(0, 1)) >= high)
    ]
    return min(holders, key=lambda i: volumes[i]) if holders else None


def _piece(piece: Mesh, volume: float, check: bool, kept: int | None):
    """One piece (m) as a faceted solid (mm) and the candidate it is. Unchecked: the weld
    (or its repair) as it comes; `kept`: that candidate; else the first sound one, or None."""
    solid, whole = faceted(piece) if not kept else (None, False)
    if not check or kept == 0:
        return solid, 0
    target = abs(volume) * MM**3
    if kept is None and whole and _sound(solid, target):
        return solid, 0
    for k, candidate in enumerate(_candidates(piece, volume), 1):
        if kept is not None and k != kept:
            continue
        if not len(candidate.faces):  # a coarser copy of a thin part can collapse to nothing
            continue
        solid, whole = faceted(candidate)
        if kept is not None or (whole and _sound(solid, target)):
            return solid, k
    return None, None


def _candidates(piece: Mesh, volume: float):
    """Coarser copies of the piece (m), then its convex hull where that holds the piece's
    volume within `VOLUME_SLACK`; an inward-facing piece (a cavity) is turned outward for
    manifold3d and back."""
    import manifold3d as mf

    from simkit.derive.solids import to_mesh

    inward = volume < 0
    used, local = np.unique(np.asarray(piece.faces).ravel(), return_inverse=True)
    faces = local.reshape(-1, 3)[:, ::-1] if inward else local.reshape(-1, 3)
    solid = mf.Manifold(
        mf.Mesh64(
            vert_properties=np.ascontiguousarray(piece.vertices[used], np.float64),
            tri_verts=np.ascontiguousarray(faces, np.uint64),
        )
    )
    if solid.status() != mf.Error.NoError or solid.is_empty():
        return

    def turned(m: Mesh) -> Mesh:
        return Mesh.of(m.vertices, np.asarray(m.faces)[:, ::-1]) if inward else m

    for tolerance in COARSER_M:
        yield turned(to_mesh(solid.simplify(tolerance)))
    hull = solid.hull()
    if hull.volume() <= abs(volume) * (1.0 + VOLUME_SLACK):
        yield turned(to_mesh(hull))


def _sound(solid: TopoDS_Shape, target: float) -> bool:
    """True when the solid passes BRepCheck and holds `target` (mm^3) within the slack."""
    return _valid(solid) and abs(abs(solid_volume(solid)) / target - 1.0) <= VOLUME_SLACK


def _valid(solid: TopoDS_Shape) -> bool:
    from OCP.BRepCheck import BRepCheck_Analyzer

    return bool(BRepCheck_Analyzer(solid).IsValid())
