"""Binary STL writer and reader: fixed header, float32 little-endian, no timestamps."""

from __future__ import annotations

from typing import NamedTuple, Protocol

import numpy as np


class Triangles(Protocol):
    """Anything with `vertices` (n, 3) in metres and `faces` (m, 3) vertex indices."""

    vertices: np.ndarray
    faces: np.ndarray


class StlMesh(NamedTuple):
    """A mesh read back from an STL: float64 vertices (m), int64 faces."""

    vertices: np.ndarray
    faces: np.ndarray


_RECORD = np.dtype([("normal", "<f4", 3), ("tri", "<f4", (3, 3)), ("attr", "<u2")])


def to_stl(mesh: Triangles, name: str) -> bytes:
    """Binary STL of a mesh (m). The 80-byte header holds only the solid's name."""
    tri = mesh.vertices[mesh.faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    lengths = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, lengths, out=np.zeros_like(normals), where=lengths > 0)
    records = np.zeros(len(tri), dtype=_RECORD)
    records["normal"] = normals
    records["tri"] = tri
    header = f"simkit {name}".encode("ascii", "replace")[:80].ljust(80, b" ")
    return header + np.uint32(len(tri)).astype("<u4").tobytes() + records.tobytes()


def from_stl(data: bytes) -> StlMesh:
    """Read a binary STL written by `to_stl` (vertices merged exactly)."""
    count = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
    records = np.frombuffer(data, dtype=_RECORD, count=count, offset=84)
    corners = records["tri"].reshape(-1, 3).astype(np.float64)
    unique, inverse = np.unique(corners, axis=0, return_inverse=True)
    return StlMesh(unique, inverse.reshape(-1, 3).astype(np.int64))
