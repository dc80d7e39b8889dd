"""An open mesh is replaced by its convex hull on import (importer/translate/meshes.py). manifold3d
builds that hull on parallel threads and lists the same triangles in a varying order, so a
re-import wrote different STL bytes (issue 22's invariant: a re-import is byte-identical).
The importer now writes the hull's triangles in one canonical order."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from simkit.importer.translate.meshes import MeshWriter, closed_solid
from simkit.model.robot import canonical_triangles


def open_cloud_mesh(points: int = 6000):
    """A dense open mesh (a sphere's point cloud with one cap cut off): not a closed solid,
    so the importer takes its convex hull."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=5, radius=0.05)
    jitter = np.random.default_rng(7).normal(scale=1e-4, size=sphere.vertices.shape)
    sphere = trimesh.Trimesh(sphere.vertices + jitter, sphere.faces, process=False)
    keep = sphere.triangles_center[:, 2] < 0.045
    cut = trimesh.Trimesh(sphere.vertices, sphere.faces[keep], process=False)
    assert not cut.is_watertight and len(cut.vertices) >= points // 2
    return cut


def test_an_open_mesh_becomes_a_hull_in_canonical_triangle_order():
    _vertices, faces, repair = closed_solid(open_cloud_mesh())
    assert repair == "hull"
    assert np.array_equal(faces, canonical_triangles(faces))
    assert (faces[:, 0] < faces[:, 1]).all() and (faces[:, 0] < faces[:, 2]).all()


def test_canonical_order_keeps_each_triangles_winding():
    faces = np.array([[5, 2, 9], [3, 1, 4], [7, 8, 0]])
    ordered = canonical_triangles(faces)
    turns = {tuple(np.roll(f, k)) for f in faces for k in range(3)}
    assert all(tuple(f) in turns for f in ordered)  # turned, never flipped
    assert [tuple(f) for f in ordered] == [(0, 7, 8), (1, 4, 3), (2, 9, 5)]


@pytest.mark.slow
def test_writing_the_same_open_mesh_again_gives_the_same_bytes(tmp_path: Path):
    source = tmp_path / "shell.stl"
    source.write_bytes(open_cloud_mesh().export(file_type="stl"))
    written = set()
    for attempt in range(12):
        out = tmp_path / f"out{attempt}"
        info = MeshWriter(out).write(source, (1.0, 1.0, 1.0))
        assert info.repair == "hull"
        written.add((out / info.file).read_bytes())
    assert len(written) == 1
