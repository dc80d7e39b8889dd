"""Closed faceted Open CASCADE solids of triangle meshes (mm), for the STEP assembly.

Vertices within `WELD_MM` are welded first (Open CASCADE cannot make a shorter edge); where
that leaves no whole shell, shellfix.py repairs the weld and it is retried at coarser welds.
OCP is imported inside the functions so that a build without STEP never loads it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from simkit.derive.shellfix import over_shared, unpinched, without_needles
from simkit.model.robot import Mesh

if TYPE_CHECKING:
    from OCP.TopoDS import TopoDS_Shape

#: Metres to millimetres: the model is SI, the STEP file is in millimetres.
MM = 1000.0

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
    nodes, triangles = merged(points, triangles, weld)
    if not repair:
        return nodes, triangles
    if over_shared(triangles):
        nodes, triangles = unpinched(nodes, triangles)
    return nodes, without_needles(nodes, triangles, weld)


def merged(points: np.ndarray, triangles: np.ndarray, weld: float) -> tuple[np.ndarray, np.ndarray]:
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
    """`faceted` without its verdict: the solid, whole or not."""
    return faceted(mesh)[0]


def faceted(mesh: Mesh) -> tuple[TopoDS_Shape, bool]:
    """A closed, connected triangle mesh (m, outward winding) as one faceted solid (mm), and
    True when its shell is whole (a face per triangle, no edge on more than two).

    Open CASCADE's `BRepBuilderAPI_MakeShapeOnMesh` makes one planar face per triangle with
    one shared edge per mesh edge (by vertex index, so a mesh that touches itself at an edge
    or a vertex still gives the right shell) in C++, ten times faster than building the
    faces one by one from Python; the faces keep the triangles' outward winding. Where no
    repair makes the shell whole, the plain weld is returned, as before the repairs.
    """

    faces = np.asarray(mesh.faces, dtype=int)
    used, local = np.unique(faces.ravel(), return_inverse=True)
    points = np.asarray(mesh.vertices, dtype=float)[used] * MM
    first, whole = _closed_solid(*_welded(points, local.reshape(-1, 3), WELD_MM, False))
    if whole:
        return first, True
    for weld in REPAIR_WELDS_MM:
        solid, whole = _closed_solid(*_welded(points, local.reshape(-1, 3), weld, True))
        if whole:
            return solid, True
    return first, False


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


def solid_volume(shape: TopoDS_Shape) -> float:
    """Volume of an Open CASCADE shape in its units cubed (mm^3 here; < 0 inside out)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return float(props.Mass())
