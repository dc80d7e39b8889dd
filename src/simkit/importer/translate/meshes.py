"""Mesh files of a URDF: load STL/OBJ/DAE with trimesh, bake the URDF scale, make them a
closed solid simkit can use, and write them as binary STL under the output folder.

simkit's link solid is a closed manifold (manifold3d). Many CAD exports are not: split
vertices are welded first; a mesh that is still open is replaced by its convex hull, and the
caller records that as an estimate with the reason.
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from simkit.model.robot import canonical_triangles, edge_uses

#: COLLADA Y_UP to a Z-up frame: file (x, y, z) -> (x, -z, y)
Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def is_y_up(path: Path) -> bool:
    """A COLLADA file whose `<asset>` says `<up_axis>Y_UP</up_axis>` (up_axis.py decides
    whether a URDF's such meshes are turned)."""
    if path.suffix.lower() != ".dae" or not path.is_file():
        return False
    head = path.read_bytes()[:65536].decode("utf-8", "replace")
    return re.search(r"<up_axis>\s*Y_UP\s*</up_axis>", head) is not None


MESH_DIR = "meshes"
SUPPORTED = (".stl", ".obj", ".dae")


@dataclass(frozen=True)
class MeshInfo:
    """One written mesh: its path relative to the spec, how it was made, and facts about it."""

    file: str
    repair: str  # "" (closed as given), "welded" or "hull" (open: convex hull used)
    convex: bool
    rgba: tuple[float, float, float, float] | None
    triangles: int


def _load(path: Path):
    import trimesh

    loaded = trimesh.load(str(path), force="mesh", process=True)
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise ValueError("no triangles in mesh")
    return loaded


def _colour(mesh) -> tuple[float, float, float, float] | None:
    """The mesh's own main colour (DAE/OBJ materials), 0..1, if it has one."""
    visual = mesh.visual
    try:
        rgba = visual.main_color if visual.kind == "vertex" or visual.kind == "face" else None
        if rgba is None and getattr(visual, "material", None) is not None:
            rgba = visual.material.main_color
    except (AttributeError, ValueError):
        return None
    if rgba is None:
        return None
    return tuple(round(float(c) / 255.0, 4) for c in np.asarray(rgba)[:4])  # type: ignore[return-value]


def _is_solid(vertices: np.ndarray, faces: np.ndarray) -> bool:
    import manifold3d as mf

    solid = mf.Manifold(
        mf.Mesh(vert_properties=np.asarray(vertices, np.float32), tri_verts=faces.astype(np.uint32))
    )
    return solid.status() == mf.Error.NoError and not solid.is_empty() and solid.volume() > 0


def _edges_paired(faces: np.ndarray) -> bool:
    """True when every edge has an even number of triangles (two, or four where a solid
    touches itself): no other mesh can be wound into a closed manifold, so a CAD mesh with
    open edges goes straight to its hull without trimesh's slow winding walk."""
    return bool((edge_uses(faces) % 2 == 0).all())


def closed_solid(mesh) -> tuple[np.ndarray, np.ndarray, str]:
    """Vertices, faces and the repair done: none, welded vertices, or the convex hull."""
    import trimesh

    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    if _is_solid(v, f):
        return v, f, ""
    welded = trimesh.Trimesh(np.asarray(mesh.vertices), np.asarray(mesh.faces), process=False)
    welded.merge_vertices(merge_tex=True, merge_norm=True, digits_vertex=6)
    welded.update_faces(welded.nondegenerate_faces())
    welded.remove_unreferenced_vertices()
    if len(welded.faces) and _edges_paired(np.asarray(welded.faces)):
        trimesh.repair.fix_normals(welded)  # a Python walk over the faces: seconds on CAD
        if _is_solid(welded.vertices, welded.faces):
            return np.asarray(welded.vertices), np.asarray(welded.faces), "welded"
    return (*_hull(np.asarray(mesh.vertices)), "hull")


def _hull(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The convex hull as a closed manifold at STL's float32 precision. manifold3d's hull,
    not qhull's: on a thin part (a propeller blade 1 cm thick) qhull leaves sliver
    facets that are not a manifold once written as float32. Its triangles come back in a
    varying order, so they are put in one (`canonical_triangles`): a re-import is byte-identical."""
    import manifold3d as mf

    hull = mf.Manifold.hull_points(np.asarray(points, np.float32)).to_mesh()
    vertices = np.array(hull.vert_properties, dtype=np.float64)[:, :3]
    return vertices, canonical_triangles(np.array(hull.tri_verts, dtype=np.int64))


#: m: the largest mesh a spec holds (spec/bounds.py `size`); a larger or non-finite scaled
#: mesh (scale="1e300 1 1") is left out with a report line, not written with 0 triangles
MAX_EXTENT = 100.0


class MeshWriter:
    """Writes each distinct (file, scale) once, as meshes/NAME.stl under `out_dir`."""

    def __init__(self, out_dir: Path) -> None:
        self.out_dir = out_dir
        self.done: dict[tuple[str, tuple[float, ...]], MeshInfo] = {}
        self.names: set[str] = set()
        #: COLLADA files marked Y_UP are turned Z-up (up_axis.turn_y_up decides per URDF)
        self.turn_y_up = False

    def _name(self, path: Path, scale: tuple[float, float, float]) -> str:
        stem = re.sub(r"[^A-Za-z0-9_.-]+", "_", path.stem) or "mesh"
        if scale != (1.0, 1.0, 1.0):
            stem += "_s" + hashlib.sha256(repr(scale).encode()).hexdigest()[:6]
        name, k = stem, 2
        while name in self.names:
            name, k = f"{stem}_{k}", k + 1
        self.names.add(name)
        return f"{MESH_DIR}/{name}.stl"

    def write(self, path: Path, scale: tuple[float, float, float]) -> MeshInfo:
        """Convert (once) and return the mesh's info; ValueError if it cannot be read."""
        key = (str(path.resolve()), scale)
        if key in self.done:
            return self.done[key]
        import trimesh

        if path.suffix.lower() not in SUPPORTED:
            raise ValueError(f"unsupported mesh format '{path.suffix}' (STL, OBJ or DAE)")
        try:
            mesh = _load(path)
        except Exception as exc:  # trimesh raises many types on bad files
            raise ValueError(f"cannot read mesh: {' '.join(str(exc).split())}") from None
        if self.turn_y_up and is_y_up(path):
            turn = np.eye(4)
            turn[:3, :3] = Y_UP_TO_Z_UP
            mesh.apply_transform(turn)
        with np.errstate(over="ignore", invalid="ignore"):
            mesh.apply_scale(np.asarray(scale, float))
            extent = float(np.ptp(np.asarray(mesh.vertices), axis=0).max())
        if not np.isfinite(mesh.vertices).all() or extent > MAX_EXTENT:
            raise ValueError(f"scale {scale} makes it {extent:g} m across (at most {MAX_EXTENT:g})")
        vertices, faces, repair = closed_solid(mesh)
        if len(faces) == 0:
            raise ValueError(f"scale {scale} leaves no triangles")
        solid = trimesh.Trimesh(vertices, faces, process=False)
        rel = self._name(path, scale)
        target = self.out_dir / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(solid.export(file_type="stl"))
        info = MeshInfo(rel, repair, bool(solid.is_convex), _colour(mesh), len(faces))
        self.done[key] = info
        return info
