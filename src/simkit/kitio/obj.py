"""Wavefront OBJ writer and reader for the collision pieces (Drake's SceneGraph takes convex
hulls only from OBJ, VTK or glTF; MuJoCo, Gazebo, PyBullet and trimesh read OBJ too).

Text, LF, one `v x y z` line per vertex (metres, link frame) and one `f a b c` per triangle
(1-based, counter-clockwise seen from outside). Coordinates are rounded to float32 first, as
the binary STL stored them, so every reader sees the numbers it saw before, and written by
the one number formatter (10 significant digits, enough to give back the same float32).
"""

from __future__ import annotations

import numpy as np

from simkit.kitio.fmt import num
from simkit.kitio.stl import StlMesh, Triangles, from_stl


def to_obj(mesh: Triangles, name: str) -> bytes:
    """OBJ text of a mesh (m): a comment naming the piece, an object, vertices, triangles."""
    label = "".join(ch if ch.isalnum() or ch in "_-." else "_" for ch in name) or "mesh"
    lines = [f"# simkit {label}", f"o {label}"]
    points = np.asarray(mesh.vertices, dtype=np.float32).astype(np.float64)
    lines += [f"v {num(x)} {num(y)} {num(z)}" for x, y, z in points.tolist()]
    faces = np.asarray(mesh.faces, dtype=np.int64) + 1
    lines += [f"f {a} {b} {c}" for a, b, c in faces.tolist()]
    return ("\n".join(lines) + "\n").encode("ascii")


def from_obj(data: bytes) -> StlMesh:
    """Vertices (m) and triangles of an OBJ: `v` and `f` records (polygons fanned into
    triangles, `v/vt/vn` and negative indices accepted); everything else is ignored."""
    vertices: list[tuple[float, float, float]] = []
    faces: list[tuple[int, int, int]] = []
    for line in data.decode("utf-8").splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            vertices.append((float(parts[1]), float(parts[2]), float(parts[3])))
        elif parts[0] == "f":
            ring = [_index(token, len(vertices)) for token in parts[1:]]
            if len(ring) < 3:
                raise ValueError(f"a face with {len(ring)} corners")
            faces += [(ring[0], ring[k], ring[k + 1]) for k in range(1, len(ring) - 1)]
    points = np.array(vertices, dtype=np.float64).reshape(-1, 3)
    triangles = np.array(faces, dtype=np.int64).reshape(-1, 3)
    if triangles.size and (triangles.min() < 0 or triangles.max() >= len(points)):
        raise ValueError("a face names a vertex the file does not have")
    return StlMesh(points, triangles)


def _index(token: str, count: int) -> int:
    """0-based vertex index of an OBJ face corner (`7`, `7/2/7`, `-1`)."""
    value = int(token.split("/")[0])
    return value - 1 if value > 0 else count + value


def read_mesh(path: str, data: bytes) -> StlMesh:
    """A kit mesh file by its suffix: `.obj` (collision pieces) or binary `.stl` (visual)."""
    return from_obj(data) if path.lower().endswith(".obj") else from_stl(data)
