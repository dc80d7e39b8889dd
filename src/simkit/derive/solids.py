"""Link solids: one watertight solid per link from the spec's primitives, with manifold3d.

Union first (in spec order), then subtract the `subtract: true` primitives. Round shapes
use a fixed segment count so output is deterministic.

A mesh file of several closed parts (a glTF or CAD scene flattened to one mesh, issue 42
classes 5 and 10) is the union of its parts: manifold3d takes overlapping parts as they
come, so the mesh counted an overlap twice and an inside-out part (glTF's double-sided
materials hide winding) as negative volume, and the visual STL, the STEP solid and the mass
disagreed about what the solid is (a STEP 143 % off its STL). A part facing inward that lies
inside an outward part is that part's cavity and stays one; any other is turned outward.
"""

from __future__ import annotations

from pathlib import Path

import manifold3d as mf
import numpy as np

from simkit.errors import SpecError
from simkit.model.kinematics import rpy_matrix
from simkit.model.robot import Mesh, Shape

CIRCULAR_SEGMENTS = 48
#: A sphere curves both ways, so at 48 segments its mesh holds 1.01 % less than the true
#: sphere (a quadruped's spherical feet failed the STEP check's 1 % bound); 96 segments lose
#: about 0.25 %.
SPHERE_SEGMENTS = 2 * CIRCULAR_SEGMENTS


def _placed(solid: mf.Manifold, shape: Shape) -> mf.Manifold:
    rot = rpy_matrix(shape.rpy)
    affine = np.hstack([rot, np.asarray(shape.xyz, float).reshape(3, 1)])
    return solid.transform(affine.tolist())


def _load_mesh(shape: Shape, base_dir: Path) -> mf.Manifold:
    import trimesh  # lazy: trimesh import is slow and only mesh-sourced links need it

    path = (base_dir / shape.file).resolve() if shape.file else None
    if path is None or not path.is_file():
        raise SpecError(str(base_dir), None, "solid.file", f"mesh file not found: {shape.file}")
    try:
        mesh = trimesh.load_mesh(path, force="mesh", process=True)
        verts = np.asarray(mesh.vertices, dtype=np.float32) * shape.scale
        faces = np.asarray(mesh.faces, np.uint32)
    except Exception as exc:  # trimesh raises many kinds on a file it cannot read
        why = " ".join(f"{type(exc).__name__}: {exc}".split())[:200]
        raise SpecError(str(path), None, "solid.file", f"cannot read mesh: {why}") from None
    if faces.ndim != 2 or len(faces) == 0:
        raise SpecError(str(path), None, "solid.file", "mesh has no triangles")
    solid = mf.Manifold(mf.Mesh(vert_properties=verts, tri_verts=faces))
    if solid.status() != mf.Error.NoError or solid.is_empty():
        raise SpecError(str(path), None, "solid.file", "mesh is not a closed, manifold solid")
    return union_of_parts(solid)


#: relative: parts whose union holds their summed volume to this are disjoint (kept as read)
DISJOINT_SLACK = 1e-9
#: bumped when `union_of_parts` changes what a mesh file's solid is (per_link.py's cache key)
PARTS_RULE = 1


def _turned(part: mf.Manifold) -> mf.Manifold:
    """`part` with its triangles wound the other way (an inside-out part turned outward)."""
    out = part.to_mesh64()
    faces = np.array(np.asarray(out.tri_verts)[:, ::-1], np.uint64, order="C")  # writable copies
    verts = np.array(np.asarray(out.vert_properties)[:, :3], np.float64, order="C")
    return mf.Manifold(mf.Mesh64(vert_properties=verts, tri_verts=faces))


def union_of_parts(solid: mf.Manifold) -> mf.Manifold:
    """The region a mesh of closed parts encloses (module doc): each outward part less the
    inward parts it wholly holds (its cavities), united with every other part turned
    outward. A mesh of one outward part, or of disjoint parts with no stray inward one, is
    returned as read (the same bytes as before)."""
    parts = solid.decompose()
    if len(parts) < 2 and solid.volume() > 0:
        return solid
    outward = [p for p in parts if p.volume() > 0]
    hosted: dict[int, list[mf.Manifold]] = {}
    stray = []
    for part in (p for p in parts if p.volume() <= 0):
        cavity = _turned(part)
        host = next((i for i, o in enumerate(outward) if _holds(o, cavity)), None)
        if host is None:
            stray.append(cavity)
        else:
            hosted.setdefault(host, []).append(cavity)
    if not stray and _disjoint(outward):
        return solid
    pieces = [
        o - mf.Manifold.batch_boolean(hosted[i], mf.OpType.Add) if i in hosted else o
        for i, o in enumerate(outward)
    ]
    pieces += stray
    return mf.Manifold.batch_boolean(pieces, mf.OpType.Add) if len(pieces) > 1 else pieces[0]


def _holds(outer: mf.Manifold, inner: mf.Manifold) -> bool:
    """True when `outer` holds all of `inner` (both outward); boxes first, so a mesh of
    many parts pays a Boolean only for the pairs whose boxes nest."""
    low, high = np.split(np.asarray(outer.bounding_box()), 2)
    in_low, in_high = np.split(np.asarray(inner.bounding_box()), 2)
    if np.any(in_low < low) or np.any(in_high > high):
        return False
    return (outer ^ inner).volume() >= inner.volume() * (1.0 - 1e-6)


def _disjoint(parts: list[mf.Manifold]) -> bool:
    """True when the parts' union holds their summed volume: no two overlap."""
    if len(parts) < 2:
        return True
    total = sum(p.volume() for p in parts)
    union = mf.Manifold.batch_boolean(parts, mf.OpType.Add).volume()
    return abs(union / total - 1.0) <= DISJOINT_SLACK


def primitive_solid(shape: Shape, base_dir: Path | None = None) -> mf.Manifold:
    """The manifold of one primitive, placed in the link frame."""
    kind = shape.kind
    if kind == "box":
        solid = mf.Manifold.cube(tuple(shape.size), center=True)  # type: ignore[arg-type]
    elif kind == "cylinder":
        solid = mf.Manifold.cylinder(
            shape.length, shape.radius, shape.radius, CIRCULAR_SEGMENTS, center=True
        )
    elif kind == "cone":
        solid = mf.Manifold.cylinder(
            shape.length, shape.radius, shape.radius_top, CIRCULAR_SEGMENTS, center=True
        )
    elif kind == "sphere":
        solid = mf.Manifold.sphere(shape.radius, SPHERE_SEGMENTS)
    elif kind == "capsule":
        half = shape.length / 2
        ball = mf.Manifold.sphere(shape.radius, CIRCULAR_SEGMENTS)
        solid = mf.Manifold.batch_hull(
            [ball.translate((0, 0, -half)), ball.translate((0, 0, half))]
        )
    elif kind == "mesh":
        solid = _load_mesh(shape, base_dir or Path("."))
    else:  # pragma: no cover - the schema only admits the kinds above
        raise ValueError(kind)
    return _placed(solid, shape)


def link_solid(shapes: tuple[Shape, ...], base_dir: Path | None = None) -> Mesh:
    """Union the additive primitives, subtract the rest; return a watertight mesh (m)."""
    add = [primitive_solid(s, base_dir) for s in shapes if not s.subtract]
    cut = [primitive_solid(s, base_dir) for s in shapes if s.subtract]
    solid = mf.Manifold.batch_boolean(add, mf.OpType.Add) if len(add) > 1 else add[0]
    if cut:
        solid = solid - mf.Manifold.batch_boolean(cut, mf.OpType.Add)
    return to_mesh(solid)


def to_mesh(solid: mf.Manifold) -> Mesh:
    """Convert a manifold to a read-only model `Mesh` (float64 vertices)."""
    out = solid.to_mesh64() if hasattr(solid, "to_mesh64") else solid.to_mesh()
    verts = np.asarray(out.vert_properties, dtype=np.float64)[:, :3]
    faces = np.asarray(out.tri_verts, dtype=np.int64)
    return Mesh.of(verts, faces)


def is_convex_union(shapes: tuple[Shape, ...]) -> bool:
    """True when the solid is a plain union of convex primitives (no subtraction, no mesh)."""
    return bool(shapes) and all(not s.subtract and s.kind != "mesh" for s in shapes)
