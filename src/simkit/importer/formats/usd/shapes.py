"""A body's shapes as the model's collision and visual `Geometry` (read/model.py).

Each prim below a rigid body (not below a nested one) that is a Cube, Sphere, Capsule,
Cylinder or Mesh: with `PhysicsCollisionAPI` a collision, else (visible, purpose default or
render) a visual. Primitives keep their shape (sizes scaled by their transform's scale);
meshes are written as binary STL into the import's scratch folder, vertices in the link
frame (metres, every transform and scale applied), triangulated as fans. A visual's colour:
its bound material's UsdPreviewSurface `diffuseColor` (and `opacity`), else its
`primvars:displayColor`. A mesh collider's `physics:approximation` is reported where it is
not the mesh itself (the kit makes its own convex pieces).

Collision meshes that are children of one prim other than the body (a grouping Xform or
Scope), two or more and each convex, are the convex pieces of one source: a convex
decomposition its author made, such as the URDF converter's prim for one `<collision>` mesh
file holding many objects. Each stays its own piece, marked as of that source
(the model's `Geometry.piece_of`), so that they count once against the cap on given collision
sources, as the URDF import counts that one file once (it reads the file as one shape, whose
one convex hull the kit takes; here each piece keeps its own hull, merged pairwise down to
the kit's ten). A mesh right below the body, or one of a group with a concave mesh, counts
as its own source.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from simkit.importer.formats.usd import poses
from simkit.importer.read.model import At, Geometry, Material, Shape

SHAPES = ("Cube", "Sphere", "Capsule", "Cylinder", "Mesh")


@dataclass
class Collider:
    """A collision `Geometry` and its shape's own MassAPI `density` (kg/m^3) and `mass` (kg),
    0 where not given (UsdPhysics: a collider's own MassAPI sets its share of the body's
    mass; mass.py reads them)."""

    geometry: Geometry
    density: float = 0.0
    mass: float = 0.0


@dataclass
class Shapes:
    """A body's shapes in its link frame: visuals, colliders, the mesh approximations met."""

    visuals: list[Geometry] = field(default_factory=list)
    colliders: list[Collider] = field(default_factory=list)
    approximations: list[str] = field(default_factory=list)


def prims_of(body, bodies: set[str]):
    """The shape prims of `body` (instance proxies included), not those of a nested body."""
    from pxr import Usd

    every = Usd.TraverseInstanceProxies(Usd.PrimDefaultPredicate)
    walk = iter(Usd.PrimRange(body, every))
    for prim in walk:
        if prim != body and str(prim.GetPath()) in bodies:
            walk.PruneChildren()
            continue
        if prim.GetTypeName() in SHAPES:
            yield prim


def shapes(name: str, body, bodies: set[str], frame: np.ndarray, ctx) -> Shapes:
    """The collisions and visuals of `body`, link `name`; `frame`: the link frame in the body
    frame (m); `ctx`: the tree's Context (cache, units, scratch)."""
    from pxr import UsdGeom, UsdPhysics

    out = Shapes()
    to_link = poses.inv(frame)
    meshes: dict[str, list] = {}  # parent prim path -> the indices of its collision meshes
    for prim in prims_of(body, bodies):
        full = poses.relative(ctx.cache, prim, body, ctx.units.meters)
        full = to_link @ full
        collides = prim.HasAPI(UsdPhysics.CollisionAPI)
        imageable = UsdGeom.Imageable(prim)
        shown = (
            imageable.ComputeVisibility() != UsdGeom.Tokens.invisible
            and imageable.ComputePurpose() in (UsdGeom.Tokens.default_, UsdGeom.Tokens.render)
        )
        if collides:
            geometry = _geometry(name, "collision", prim, full, ctx)
            if geometry is not None:
                collider = Collider(geometry)
                if prim.HasAPI(UsdPhysics.MassAPI):
                    _own_mass(collider, UsdPhysics.MassAPI(prim), ctx.units)
                if prim.GetTypeName() == "Mesh":
                    where = str(prim.GetParent().GetPath())
                    meshes.setdefault(where, []).append(len(out.colliders))
                out.colliders.append(collider)
            if prim.HasAPI(UsdPhysics.MeshCollisionAPI):
                how = UsdPhysics.MeshCollisionAPI(prim).GetApproximationAttr().Get()
                out.approximations.append(str(how or "none"))
        elif shown:
            geometry = _geometry(name, "visual", prim, full, ctx)
            if geometry is not None:
                out.visuals.append(replace(geometry, material=_colour(prim)))
    meshes.pop(str(body.GetPath()), None)
    for parent, indices in sorted(meshes.items()):
        _pieces(parent, [out.colliders[k] for k in indices])
    return out


def _pieces(parent: str, colliders: list[Collider]) -> None:
    """Mark the collision meshes below one grouping prim `parent` as the pieces of one
    source (module docstring) where there are two or more and each is convex."""
    import trimesh

    if len(colliders) < 2:
        return
    for collider in colliders:
        path = collider.geometry.shape.filename
        if not trimesh.load_mesh(path, file_type="stl").is_convex:
            return
    for collider in colliders:
        collider.geometry = replace(collider.geometry, piece_of=parent)


def _own_mass(collider: Collider, api, units) -> None:
    """Record a collider's MassAPI density and mass (stage units to kg/m^3 and kg)."""
    density, mass = api.GetDensityAttr(), api.GetMassAttr()
    if density and density.HasAuthoredValue() and float(density.Get()) > 0:
        collider.density = float(density.Get()) * units.kilograms / units.meters**3
    if mass and mass.HasAuthoredValue() and float(mass.Get()) > 0:
        collider.mass = float(mass.Get()) * units.kilograms


def _f32(values) -> np.ndarray:
    """Sizes made from float32 scales (xformOp:scale is float3) as the decimals written."""
    return np.array([float(str(np.float32(v))) for v in np.ravel(values)])


def _geometry(name: str, tag: str, prim, full: np.ndarray, ctx) -> Geometry | None:
    """One collision or visual `Geometry` (`tag`) of a shape prim of link `name` (transform
    `full` in the link frame, scale included); None for an empty or flat mesh (listed)."""
    kind = prim.GetTypeName()
    pose, scale = rigid(full)
    m = ctx.units.meters
    if kind == "Mesh":
        path = _stl(prim, full, ctx.scratch)
        if path is None:
            what = f"links.{name}.{tag}.{prim.GetName()}"
            ctx.listed.append((what, "a mesh with no faces or no volume (flat): left out"))
            return None
        pose = np.eye(4)
        shape = Shape("mesh", At("mesh"), filename=str(path))
    elif kind == "Cube":
        size = float(prim.GetAttribute("size").Get() or 2.0) * m * scale
        shape = Shape("box", At("box"), size=poses.floats(_f32(size)))  # type: ignore[arg-type]
    elif kind == "Sphere":
        radius = float(prim.GetAttribute("radius").Get() or 1.0) * m * float(np.max(scale))
        shape = Shape("sphere", At("sphere"), radius=poses.floats(_f32([radius]))[0])
    else:
        axis = str(prim.GetAttribute("axis").Get() or "Z")
        along = "XYZ".index(axis)
        across = [s for i, s in enumerate(scale) if i != along]
        radius = float(prim.GetAttribute("radius").Get() or 1.0) * m * float(max(across))
        height = float(prim.GetAttribute("height").Get() or 2.0) * m * float(scale[along])
        pose = pose @ poses.make(_z_to(axis), np.zeros(3))
        radius, height = poses.floats(_f32([radius, height]))
        shape = Shape(kind.lower(), At(kind.lower()), radius=radius, length=height)
    return Geometry(At(tag, prim.GetName()), poses.pose(pose), shape)


def rigid(full: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    scale = np.linalg.norm(full[:3, :3], axis=0)
    scale = np.where(scale > 0, scale, 1.0)
    u, _, vt = np.linalg.svd(full[:3, :3] / scale)
    rot = u @ vt
    return poses.make(rot if np.linalg.det(rot) > 0 else -rot, full[:3, 3]), scale


def _z_to(axis: str) -> np.ndarray:
    """The turn taking URDF's z-aligned cylinder onto USD's `axis`."""
    if axis == "X":
        return np.array([[0, 0, 1.0], [0, 1.0, 0], [-1.0, 0, 0]])
    if axis == "Y":
        return np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]])
    return np.eye(3)


def _stl(prim, full: np.ndarray, scratch: Path) -> Path | None:
    """The mesh, fan-triangulated, its vertices in the link frame (m), as a binary STL in
    `scratch` named by its content; None when it has no faces."""
    import trimesh

    points = prim.GetAttribute("points").Get()
    counts = prim.GetAttribute("faceVertexCounts").Get()
    indices = prim.GetAttribute("faceVertexIndices").Get()
    if not points or not counts or not indices:
        return None
    vertices = np.asarray(points, dtype=float)
    vertices = vertices @ full[:3, :3].T + full[:3, 3]
    flat = np.asarray(indices, dtype=np.int64)
    faces, at = [], 0
    for count in np.asarray(counts, dtype=np.int64):
        faces += [(flat[at], flat[at + k], flat[at + k + 1]) for k in range(1, int(count) - 1)]
        at += int(count)
    faces = [f for f in faces if max(f) < len(vertices)]
    if not faces or is_flat(vertices):
        return None
    mesh = trimesh.Trimesh(vertices, np.asarray(faces), process=False)
    data = mesh.export(file_type="stl")
    path = scratch / f"{prim.GetName()}_{hashlib.sha256(data).hexdigest()[:12]}.stl"
    path.write_bytes(data)
    return path


def is_flat(points: np.ndarray) -> bool:
    """Whether a mesh encloses no volume, even as its convex hull (a decal, a sheet): a kit's
    solid must be closed, so it is left out (listed)."""
    import manifold3d as mf

    if len(points) < 4:
        return True
    hull = mf.Manifold.hull_points(np.asarray(points, dtype=np.float32))
    extent = float(np.ptp(points, axis=0).max())
    return hull.is_empty() or hull.volume() <= 1e-9 * extent**3


def _colour(prim) -> Material | None:
    """The visual's `Material` colour (module docstring), when the stage gives one."""
    from pxr import UsdGeom, UsdShade

    rgba = None
    material, _ = UsdShade.MaterialBindingAPI(prim).ComputeBoundMaterial()
    if material:
        shader = material.ComputeSurfaceSource()[0]
        if shader:
            colour = shader.GetInput("diffuseColor")
            opacity = shader.GetInput("opacity")
            if colour and colour.Get() is not None:
                alpha = opacity.Get() if opacity and opacity.Get() is not None else 1.0
                rgba = [*(float(c) for c in colour.Get()), float(alpha)]
    if rgba is None:
        shown = UsdGeom.Gprim(prim).GetDisplayColorAttr().Get()
        if shown is not None and len(shown):
            rgba = [*(float(c) for c in shown[0]), 1.0]
    if rgba is None:
        return None
    name = f"usd_{hashlib.sha256(poses.fmt(rgba).encode()).hexdigest()[:8]}"
    clipped = poses.floats(np.clip(rgba, 0.0, 1.0))
    return Material(At("material", name), name, clipped)  # type: ignore[arg-type]
