"""Check of `step/NAME.step` (issue 14): re-read it with Open CASCADE and compare each link's
solids with its visual STL.

Read with STEPCAFControl_Reader: AP214 schema, millimetres, one assembly component per link
with geometry, named as the link, holding the link's solids (one for a primitive link, whose
touching primitives Open CASCADE fuses; one per separate piece for a mesh link: a CAD part
with disjoint bolts has several), every solid passing BRepCheck_Analyzer. Each link's volume
must be within 1 % of the visual STL's (the STL is the same solid tessellated with a fixed
number of segments, so it holds slightly less; a removed or added piece shows here) and its
bounding box within 1 mm of the STL's, both in the assembly origin frame at the zero pose.
The STLs are in link frames: FK from robot.json's own joints (q = 0) places them, so a moved
or missing link fails. A link robot.json lists in `geometry.step.left_out` (with its reason:
no valid solid could be made of its mesh, issue 32) must have no solid; any other missing
solid fails.
"""

from __future__ import annotations

from collections import deque

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.model.kinematics import rpy_matrix, transform

VOLUME_TOL = 0.01  # relative: 48-segment tessellation loses about 0.3 % (issue 14: 1 %)
BOUNDS_TOL = 1.0  # mm (issue 14)


def zero_pose_frames(doc: dict, origin: str) -> dict[str, np.ndarray]:
    """T_origin_frame (m) of every link and joint frame in robot.json at q = 0: movable,
    fixed and floating-base joints, walked both ways from `origin`."""
    edges: dict[str, list[tuple[str, np.ndarray]]] = {}
    joints = list(doc["joints"]) + list(doc.get("fixed_joints", []))
    if doc.get("floating_base"):
        joints.append(doc["floating_base"])
    for joint in joints:
        t = transform(joint["origin_xyz"], rpy_matrix(joint["origin_rpy"]))
        edges.setdefault(joint["parent"], []).append((joint["child"], t))
        edges.setdefault(joint["child"], []).append((joint["parent"], np.linalg.inv(t)))
    poses = {origin: np.eye(4)}
    todo = deque([origin])
    while todo:
        node = todo.popleft()
        for other, t in edges.get(node, []):
            if other not in poses:
                poses[other] = poses[node] @ t
                todo.append(other)
    return poses


def read_step(path) -> tuple[dict[str, list], str]:
    """{component name: [solids placed in the assembly frame (mm)]} and the file's text."""
    from OCP.IFSelect import IFSelect_ReturnStatus
    from OCP.Interface import Interface_Static
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    from simkit.check.readers.step import solids_of

    _quiet()
    Interface_Static.SetCVal_s("xstep.cascade.unit", "MM")
    doc = TDocStd_Document(TCollection_ExtendedString("XmlXCAF"))
    XCAFDoc_DocumentTool.SetLengthUnit_s(doc, 0.001)
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    for off in (reader.SetColorMode, reader.SetLayerMode, reader.SetPropsMode):
        off(False)  # names and shapes are all the check reads
    if reader.ReadFile(str(path)) != IFSelect_ReturnStatus.IFSelect_RetDone:
        raise ValueError(f"{path}: Open CASCADE cannot read this STEP file")
    if not reader.Transfer(doc):
        raise ValueError(f"{path}: Open CASCADE cannot translate this STEP file")
    parts: dict[str, list] = {}
    for name, shape in _components(doc):
        parts.setdefault(name, []).extend(solids_of(shape))
    return parts, path.read_text(encoding="utf-8", errors="replace")


def _quiet() -> None:
    from OCP.Message import Message, Message_Gravity

    for printer in Message.DefaultMessenger_s().Printers():
        printer.SetTraceLevel(Message_Gravity.Message_Warning)


def _name(label) -> str:
    from OCP.TDataStd import TDataStd_Name

    attr = TDataStd_Name()
    return attr.Get().ToExtString() if label.FindAttribute(TDataStd_Name.GetID_s(), attr) else ""


def _components(doc) -> list[tuple[str, object]]:
    """(product name, located shape) for every leaf part, walking nested assemblies."""
    from OCP.collections import Sequence_TDF_Label
    from OCP.TDF import TDF_Label
    from OCP.XCAFDoc import XCAFDoc_DocumentTool, XCAFDoc_ShapeTool

    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())
    free = Sequence_TDF_Label()
    tool.GetFreeShapes(free)
    out = []
    todo = [(free.Value(i), None) for i in range(1, free.Length() + 1)]
    while todo:
        label, location = todo.pop(0)
        if not XCAFDoc_ShapeTool.IsAssembly_s(label):
            shape = XCAFDoc_ShapeTool.GetShape_s(label)
            out.append((_name(label), shape if location is None else shape.Moved(location)))
            continue
        children = Sequence_TDF_Label()
        XCAFDoc_ShapeTool.GetComponents_s(label, children, False)
        for i in range(1, children.Length() + 1):
            child = children.Value(i)
            ref = TDF_Label()
            XCAFDoc_ShapeTool.GetReferredShape_s(child, ref)
            here = XCAFDoc_ShapeTool.GetLocation_s(child)
            todo.append((ref, here if location is None else location.Multiplied(here)))
    return out


def _mesh_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    tri = vertices[faces]
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)


def _visual(kit: Kit, path: str, pose: np.ndarray) -> tuple[float, np.ndarray]:
    """Volume (mm^3) and bounds (mm) of a visual STL placed at `pose` (T_origin_link, m)."""
    from simkit.kitio.stl import from_stl

    mesh = from_stl(kit.path(path).read_bytes())
    points = (mesh.vertices @ pose[:3, :3].T + pose[:3, 3]) * 1000.0
    box = np.array([points.min(axis=0), points.max(axis=0)])
    return _mesh_volume(mesh.vertices, mesh.faces) * 1e9, box


def check_step(kit: Kit) -> list[Finding]:
    """The STEP assembly against robot.json and the visual meshes (see module doc)."""
    entry = kit.doc.get("geometry", {}).get("step")
    if entry is None:
        stray = (
            sorted(p.name for p in kit.path("step").glob("*")) if kit.path("step").is_dir() else []
        )
        return [
            require(
                "step.file",
                not stray,
                f"robot.json: no STEP (--no-step); step/ holds {stray or 'nothing'}",
            )
        ]
    from OCP.BRepCheck import BRepCheck_Analyzer

    parts, text = read_step(kit.path(entry["file"]))
    poses = zero_pose_frames(kit.doc, entry["origin"])
    visuals = {
        link["name"]: _visual(kit, link["mesh"]["visual"], poses[link["name"]])
        for link in kit.doc["links"]
        if link["mesh"]["visual"]
    }
    counts = {name: len(solids) for name, solids in parts.items()}
    left_out = {e.get("link"): e.get("why") for e in entry.get("left_out", [])}
    wrong = [f"{n}: left out with no reason" for n in sorted(left_out) if not left_out[n]]
    wrong += [f"{n}: left out, yet has solids" for n in sorted(left_out) if counts.get(n)]
    wrong += [
        f"{n}: left out, not a link with a mesh" for n in sorted(set(left_out) - set(visuals))
    ]
    visuals = {n: v for n, v in visuals.items() if n not in left_out}
    wrong += [f"{n}: no solid" for n in sorted(visuals) if not counts.get(n)]
    # a product without solids that is no link is the empty assembly of a robot with no
    # geometry at all (an imported URDF of inertials only), which the reader sees as a leaf
    extra = sorted(n for n in set(counts) - set(visuals) if counts[n])
    wrong += [f"{n}: not a link with geometry" for n in extra]
    findings = [
        require(
            "step.schema",
            "AUTOMOTIVE_DESIGN" in text and "SI_UNIT(.MILLI.,.METRE.)" in text,
            "ISO 10303-21 AP214 (AUTOMOTIVE_DESIGN) in millimetres",
        ),
        require(
            "step.products",
            not wrong,
            f"one product per link with geometry, named as the link, holding its solids "
            f"({len(visuals)} links; "
            + (f"left out as robot.json says: {len(left_out)}; " if left_out else "")
            + f"wrong: {', '.join(wrong) or 'none'})",
        ),
    ]
    invalid = [
        n
        for n, solids in sorted(parts.items())
        if any(not BRepCheck_Analyzer(s).IsValid() for s in solids)
    ]
    findings.append(
        require("step.brepcheck", not invalid, f"every solid passes BRepCheck ({invalid or 'all'})")
    )
    return findings + _against_meshes(parts, visuals, entry["origin"])


def _against_meshes(parts: dict, visuals: dict, origin: str) -> list:
    """Volume and bounding box of each link's solids against its visual STL (mm)."""
    from simkit.check.readers.step import bounds, volume

    worst_volume, worst_bounds, off_volume, off_bounds = 0.0, 0.0, [], []
    for name, (ref_volume, ref_box) in sorted(visuals.items()):
        if not parts.get(name):
            continue  # step.products reports it
        boxes = np.array([bounds(solid) for solid in parts[name]])
        box = np.array([boxes[:, 0].min(axis=0), boxes[:, 1].max(axis=0)])
        dv = abs(sum(volume(solid) for solid in parts[name]) / ref_volume - 1.0)
        db = float(np.abs(box - ref_box).max())
        worst_volume, worst_bounds = max(worst_volume, dv), max(worst_bounds, db)
        off_volume += [name] if dv > VOLUME_TOL else []
        off_bounds += [name] if db > BOUNDS_TOL else []
    return [
        require(
            "step.volume",
            not off_volume,
            f"each link's solids' volume within {VOLUME_TOL:.0%} of its visual STL's "
            f"(worst {worst_volume:.3%}; off: {', '.join(off_volume) or 'none'})",
        ),
        require(
            "step.bounds",
            not off_bounds,
            f"each link's bounding box within {BOUNDS_TOL:g} mm of its visual STL's in "
            f"{origin} at the zero pose (worst {worst_bounds:.3g} mm; off: "
            f"{', '.join(off_bounds) or 'none'})",
        ),
    ]
