"""Exact B-rep link solids (Open CASCADE, through cadquery-ocp) from the spec's primitives.

The same primitive tree that `solids.py` meshes with manifold3d, built as true boxes,
cylinders, cones and spheres: union in spec order, then subtract the `subtract: true`
primitives. A link that uses a mesh file becomes closed faceted solids of its derived visual
mesh, one per separate piece (the mesh already holds the union and difference). Lengths are
millimetres, the unit of the STEP file, in the link frame. OCP is imported inside the
functions so that a build without STEP never loads it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from simkit.derive.shellfix import over_shared, unpinched, without_needles
from simkit.model.kinematics import rpy_matrix
from simkit.model.robot import Link, Mesh, Shape

if TYPE_CHECKING:
    from OCP.TopoDS import TopoDS_Shape

#: Metres to millimetres: the model is SI, the STEP file is in millimetres.
MM = 1000.0


def trsf(matrix: np.ndarray, scale: float = MM) -> Any:
    """A `gp_Trsf` from a 4x4 rigid transform whose translation (m) is scaled by `scale`."""
    from OCP.gp import gp_Trsf

    m = np.asarray(matrix, dtype=float)
    out = gp_Trsf()
    t = m[:3, 3] * scale
    out.SetValues(*(float(v) for row in range(3) for v in (*m[row, :3], t[row])))
    return out


def _round(shape: Shape) -> TopoDS_Shape:
    """A cylinder, cone or capsule along local z, centred on the origin (mm)."""
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeCone, BRepPrimAPI_MakeCylinder
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

    radius, length = float(shape.radius) * MM, float(shape.length or 0.0) * MM
    axis = gp_Ax2(gp_Pnt(0.0, 0.0, -length / 2), gp_Dir(0.0, 0.0, 1.0))
    if shape.kind == "cone" and shape.radius_top != shape.radius:
        top = float(shape.radius_top) * MM
        return BRepPrimAPI_MakeCone(axis, radius, top, length).Shape()
    if shape.kind in ("cylinder", "cone"):
        return BRepPrimAPI_MakeCylinder(axis, radius, length).Shape()
    return _capsule(radius, length)


def _capsule(radius: float, length: float) -> TopoDS_Shape:
    """A capsule along z (mm): its half-profile (two quarter arcs joined by a line) turned
    about z, one solid with no Boolean operation (faster and cleaner than a fuse)."""
    import math

    from OCP.BRepBuilderAPI import (
        BRepBuilderAPI_MakeEdge,
        BRepBuilderAPI_MakeFace,
        BRepBuilderAPI_MakeWire,
    )
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeRevol
    from OCP.GC import GC_MakeArcOfCircle
    from OCP.gp import gp_Ax1, gp_Dir, gp_Pnt

    h, r, d = length / 2, radius, radius / math.sqrt(2.0)
    bottom, top = gp_Pnt(0, 0, -h - r), gp_Pnt(0, 0, h + r)
    low, high = gp_Pnt(r, 0, -h), gp_Pnt(r, 0, h)
    edges = [
        BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(bottom, gp_Pnt(d, 0, -h - d), low).Value()),
        BRepBuilderAPI_MakeEdge(low, high),
        BRepBuilderAPI_MakeEdge(GC_MakeArcOfCircle(high, gp_Pnt(d, 0, h + d), top).Value()),
        BRepBuilderAPI_MakeEdge(top, bottom),
    ]
    wire = BRepBuilderAPI_MakeWire()
    for edge in edges:
        wire.Add(edge.Edge())
    face = BRepBuilderAPI_MakeFace(wire.Wire(), True).Face()
    axis = gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1))
    return BRepPrimAPI_MakeRevol(face, axis, 2 * math.pi).Shape()


def primitive_shape(shape: Shape) -> TopoDS_Shape:
    """One primitive as an exact solid, placed in the link frame (mm)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Transform
    from OCP.BRepPrimAPI import BRepPrimAPI_MakeBox, BRepPrimAPI_MakeSphere
    from OCP.gp import gp_Pnt

    if shape.kind == "box":
        x, y, z = (float(v) * MM for v in shape.size or (0, 0, 0))
        solid = BRepPrimAPI_MakeBox(gp_Pnt(-x / 2, -y / 2, -z / 2), x, y, z).Shape()
    elif shape.kind == "sphere":
        solid = BRepPrimAPI_MakeSphere(float(shape.radius) * MM).Shape()
    elif shape.kind in ("cylinder", "cone", "capsule"):
        solid = _round(shape)
    else:  # mesh primitives are handled per link (faceted_solid)
        raise ValueError(f"no exact solid for a '{shape.kind}' primitive")
    pose = np.eye(4)
    pose[:3, :3] = rpy_matrix(shape.rpy)
    pose[:3, 3] = shape.xyz
    return BRepBuilderAPI_Transform(solid, trsf(pose), True).Shape()


def _boolean(first: TopoDS_Shape, others: list[TopoDS_Shape], cut: bool) -> TopoDS_Shape:
    """`first` fused with (or, `cut`, minus) all of `others` in one Boolean operation, with
    coplanar and coaxial faces merged afterwards (ShapeUpgrade_UnifySameDomain)."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut, BRepAlgoAPI_Fuse
    from OCP.collections import List_TopoDS_Shape
    from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain

    if not others:
        return first
    args, tools = List_TopoDS_Shape(), List_TopoDS_Shape()
    args.Append(first)
    for other in others:
        tools.Append(other)
    op = BRepAlgoAPI_Cut() if cut else BRepAlgoAPI_Fuse()
    op.SetArguments(args)
    op.SetTools(tools)
    op.SetUseOBB(True)  # oriented boxes: fewer candidate face pairs to intersect
    op.SetRunParallel(False)  # same result either way; serial keeps the work predictable
    op.Build()
    if not op.IsDone():
        raise RuntimeError("Open CASCADE Boolean operation failed")
    unify = ShapeUpgrade_UnifySameDomain(op.Shape(), True, True, False)
    unify.Build()
    return unify.Shape()


def _components(faces: np.ndarray) -> list[np.ndarray]:
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


def mesh_solid(mesh: Mesh) -> TopoDS_Shape:
    """A closed mesh (m) as solids (mm): one faceted solid per vertex-connected outer piece,
    with the pieces that face inward (cavities) as inner shells of the smallest outer piece
    whose box holds them; a compound when there are several solids.

    No Boolean fuse: the mesh is already manifold3d's union, so its pieces are disjoint or
    only touch, and fusing faceted solids of thousands of faces took minutes per link and
    could lose volume (a 2-piece knee of 3,478 triangles: 85 s and a third of its volume).
    A cavity as a solid of its own has a negative volume that a STEP reader drops.
    """
    from OCP.BRep import BRep_Builder
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Compound

    vertices = np.asarray(mesh.vertices, dtype=float)
    parts = _components(np.asarray(mesh.faces, dtype=int))
    volumes = [_signed_volume(vertices, part) for part in parts]
    outer = [i for i, v in enumerate(volumes) if v >= 0]
    pieces = {i: faceted_solid(Mesh.of(vertices, parts[i])) for i in outer}
    builder = BRep_Builder()
    for i, volume in enumerate(volumes):
        host = _host(vertices, parts, outer, volumes, i) if volume < 0 else None
        if host is None and volume < 0:
            pieces[i] = faceted_solid(Mesh.of(vertices, parts[i]))  # nothing holds it
        elif host is not None:
            shell = TopExp_Explorer(faceted_solid(Mesh.of(vertices, parts[i])), TopAbs_SHELL)
            builder.Add(pieces[host], shell.Current())
    solids = [pieces[i] for i in sorted(pieces)]
    if len(solids) == 1:
        return solids[0]
    compound = TopoDS_Compound()
    builder.MakeCompound(compound)
    for solid in solids:
        builder.Add(compound, solid)
    return compound


def _signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    tri = vertices[faces]
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6)


def _host(vertices, parts, outer: list[int], volumes: list[float], cavity: int) -> int | None:
    """The smallest outer piece whose bounding box holds the cavity's, or None."""
    low, high = vertices[parts[cavity]].min(axis=(0, 1)), vertices[parts[cavity]].max(axis=(0, 1))
    holders = [
        i
        for i in outer
        if np.all(vertices[parts[i]].min(axis=(0, 1)) <= low)
        and np.all(vertices[parts[i]].max(axis=(0, 1)) >= high)
    ]
    return min(holders, key=lambda i: volumes[i]) if holders else None


#: mm: vertices closer than this are one (Open CASCADE cannot make an edge shorter than its
#: 1e-7 mm tolerance; CAD meshes carry such near-duplicates)
WELD_MM = 1e-4
#: mm: where that weld leaves no whole shell, the repairs of shellfix.py at each weld in turn
REPAIR_WELDS_MM = (1e-4, 1e-3, 1e-2)


def _welded(points: np.ndarray, triangles: np.ndarray, weld: float, repair: bool):
    """`points` (mm) merged per cell of `weld` (mm), and the triangles (0-based) that keep
    three corners. With `repair`, an edge left on more than two triangles (slivers, or a
    solid touching itself along an edge) is split per fan and needles are flipped away
    (shellfix.py): Open CASCADE refuses the one and drops the other's face."""
    nodes, triangles = _merged(points, triangles, weld)
    if not repair:
        return nodes, triangles
    if over_shared(triangles):
        nodes, triangles = unpinched(nodes, triangles)
    return nodes, without_needles(nodes, triangles, weld)


def _merged(
    points: np.ndarray, triangles: np.ndarray, weld: float
) -> tuple[np.ndarray, np.ndarray]:
    """`points` merged per cell of `weld` (mm), and the triangles that keep three corners."""
    _, first, merged = np.unique(
        np.round(points / weld), axis=0, return_index=True, return_inverse=True
    )
    triangles = merged.ravel()[triangles]
    keep = (
        (triangles[:, 0] != triangles[:, 1])
        & (triangles[:, 1] != triangles[:, 2])
        & (triangles[:, 0] != triangles[:, 2])
    )
    return points[first], triangles[keep]


def faceted_solid(mesh: Mesh) -> TopoDS_Shape:
    """A closed, connected triangle mesh (m, outward winding) as one faceted solid (mm).

    Open CASCADE's `BRepBuilderAPI_MakeShapeOnMesh` makes one planar face per triangle with
    one shared edge per mesh edge (by vertex index, so a mesh that touches itself at an edge
    or a vertex still gives the right shell) in C++, ten times faster than building the
    faces one by one from Python; the faces keep the triangles' outward winding.
    """

    faces = np.asarray(mesh.faces, dtype=int)
    used, local = np.unique(faces.ravel(), return_inverse=True)
    points = np.asarray(mesh.vertices, dtype=float)[used] * MM
    first, whole = _closed_solid(*_welded(points, local.reshape(-1, 3), WELD_MM, False))
    if whole:
        return first
    for weld in REPAIR_WELDS_MM:
        solid, whole = _closed_solid(*_welded(points, local.reshape(-1, 3), weld, True))
        if whole:
            return solid
    return first  # no repair made it whole: the plain weld, as before the repairs


def _closed_solid(nodes: np.ndarray, triangles: np.ndarray) -> tuple[TopoDS_Shape, bool]:
    """One faceted solid of the triangles (0-based) on `nodes` (mm), and True when it has a
    face for every triangle and no edge on more than two: a whole, closed shell."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeShapeOnMesh
    from OCP.gp import gp_Pnt
    from OCP.Poly import Poly_Triangle, Poly_Triangulation
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS_Shell, TopoDS_Solid

    triangulation = Poly_Triangulation(len(nodes), len(triangles), False)
    for i, (x, y, z) in enumerate(nodes.tolist(), 1):
        triangulation.SetNode(i, gp_Pnt(x, y, z))
    for i, (a, b, c) in enumerate((triangles + 1).tolist(), 1):  # counted from 1
        triangulation.SetTriangle(i, Poly_Triangle(a, b, c))
    maker = BRepBuilderAPI_MakeShapeOnMesh(triangulation)
    try:
        maker.Build()
    except Exception:  # StdFail_NotDone, e.g. on a zero-area sliver, which has no plane
        return _faceted_solid_by_face(nodes, triangles)
    if not maker.IsDone():
        return _faceted_solid_by_face(nodes, triangles)
    builder = BRep_Builder()
    shell = TopoDS_Shell()
    builder.MakeShell(shell)
    explorer, count = TopExp_Explorer(maker.Shape(), TopAbs_FACE), 0
    while explorer.More():
        builder.Add(shell, explorer.Current())
        explorer.Next()
        count += 1
    shell.Closed(True)
    solid = TopoDS_Solid()
    builder.MakeSolid(solid)
    builder.Add(solid, shell)
    return solid, count == len(triangles) and not over_shared(triangles)


def _faceted_solid_by_face(nodes: np.ndarray, triangles: np.ndarray) -> tuple[TopoDS_Shape, bool]:
    """`faceted_solid` built face by face (mm nodes, 0-based triangles), for a mesh that
    OCCT's mesh builder refuses: a zero-area sliver gets no face, its edges are shared by its
    neighbours already. About ten times slower. Taken as whole (True), as it always was."""
    from OCP.BRep import BRep_Builder
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace as MakeFace
    from OCP.gp import gp_Dir, gp_Pln, gp_Pnt
    from OCP.TopoDS import TopoDS_Shell, TopoDS_Solid, TopoDS_Wire

    points = [BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, v))).Vertex() for v in nodes]
    edges: dict[tuple[int, int], Any] = {}
    builder = BRep_Builder()
    shell = TopoDS_Shell()
    builder.MakeShell(shell)
    for tri in triangles.tolist():
        a, b, c = nodes[tri]
        normal = np.cross(b - a, c - a)
        wire = TopoDS_Wire()
        builder.MakeWire(wire)
        for i, j in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            key = (min(i, j), max(i, j))
            if key not in edges:
                edges[key] = BRepBuilderAPI_MakeEdge(points[key[0]], points[key[1]]).Edge()
            builder.Add(wire, edges[key] if i < j else edges[key].Reversed())
        if np.linalg.norm(normal) <= 1e-12:
            continue
        plane = gp_Pln(gp_Pnt(*map(float, a)), gp_Dir(*map(float, normal)))
        builder.Add(shell, MakeFace(plane, wire, True).Face())
    shell.Closed(True)
    solid = TopoDS_Solid()
    builder.MakeSolid(solid)
    builder.Add(solid, shell)
    return solid, True


def link_shape(link: Link) -> TopoDS_Shape | None:
    """The link's solid in its link frame (mm), or None for a link without geometry."""
    if not link.shapes:
        return None
    if any(s.kind == "mesh" for s in link.shapes):
        return mesh_solid(link.solid) if link.solid is not None else None
    add = [primitive_shape(s) for s in link.shapes if not s.subtract]
    cut = [primitive_shape(s) for s in link.shapes if s.subtract]
    solid = _boolean(add[0], add[1:], cut=False)
    return _boolean(solid, cut, cut=True)
