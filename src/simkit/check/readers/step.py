"""Read Open CASCADE shapes back: solids, volume and bounding box (for the STEP check and
`simkit diff`). Independent of the code that built them (derive/brep.py)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from OCP.TopoDS import TopoDS_Shape
else:
    TopoDS_Shape = Any


def solids_of(shape: TopoDS_Shape) -> list[TopoDS_Shape]:
    """The solids inside `shape`, in topological order."""
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    out = []
    explorer = TopExp_Explorer(shape, TopAbs_SOLID)
    while explorer.More():
        out.append(explorer.Current())
        explorer.Next()
    return out


def volume(shape: TopoDS_Shape) -> float:
    """Volume of `shape` in its own units cubed (mm^3 for STEP shapes)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    return float(props.Mass())


def bounds(shape: TopoDS_Shape) -> np.ndarray:
    """The tight axis-aligned box of `shape`, [[xmin, ymin, zmin], [xmax, ymax, zmax]], from
    the exact geometry (no tolerance gap, no triangulation)."""
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    low, high = box.CornerMin(), box.CornerMax()
    return np.array([[low.X(), low.Y(), low.Z()], [high.X(), high.Y(), high.Z()]])
