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

from simkit.derive.facets import MM, faceted_solid
from simkit.derive.mesh_brep import Plan, mesh_shape, mesh_solid
from simkit.model.kinematics import rpy_matrix
from simkit.model.robot import Link, Shape

if TYPE_CHECKING:
    from OCP.TopoDS import TopoDS_Shape

__all__ = ["faceted_solid", "link_shape", "mesh_solid", "primitive_shape", "step_shape", "trsf"]


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


def link_shape(link: Link) -> TopoDS_Shape | None:
    """The link's solid in its link frame (mm), or None for a link without geometry or one
    whose mesh gives no valid solid (`step_shape` says why)."""
    return step_shape(link)[0]


def step_shape(link: Link, plan: Plan | None = None) -> tuple[TopoDS_Shape | None, str]:
    """`link_shape` and, where a mesh link gives no valid solid, why (else ""). `plan`: the
    candidates derive/step_plan.py kept for a mesh link (None: decide here)."""
    if not link.shapes:
        return None, ""
    if any(s.kind == "mesh" for s in link.shapes):
        return mesh_shape(link.solid, plan) if link.solid is not None else (None, "")
    add = [primitive_shape(s) for s in link.shapes if not s.subtract]
    cut = [primitive_shape(s) for s in link.shapes if s.subtract]
    solid = _boolean(add[0], add[1:], cut=False)
    return _boolean(solid, cut, cut=True), ""
