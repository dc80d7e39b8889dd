"""`importer/translate/meshes.py closed_solid`: a mesh whose triangles are wound every which way but
close up is rewound and kept ("welded"); a mesh with open edges goes straight to its convex
hull. The open case skips trimesh's winding walk, a Python loop over the faces that took
seconds on an industrial arm's CAD meshes and could not close them anyway."""

from __future__ import annotations

import numpy as np

from simkit.importer.translate.meshes import closed_solid


def box_with_flipped_faces():
    import trimesh

    box = trimesh.creation.box((0.1, 0.2, 0.3))
    faces = np.array(box.faces)
    faces[::3] = faces[::3, ::-1]  # every third triangle turned inside out
    return trimesh.Trimesh(np.array(box.vertices), faces, process=False)


def test_a_closed_mesh_wound_badly_is_rewound_and_kept():
    vertices, faces, repair = closed_solid(box_with_flipped_faces())
    assert repair == "welded"
    tri = vertices[faces]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    assert volume > 0 and np.isclose(volume, 0.1 * 0.2 * 0.3)


def test_a_mesh_with_an_open_edge_becomes_its_hull():
    import trimesh

    open_box = box_with_flipped_faces()
    open_box = trimesh.Trimesh(open_box.vertices, open_box.faces[1:], process=False)
    vertices, faces, repair = closed_solid(open_box)
    assert repair == "hull"
    tri = vertices[faces]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    assert np.isclose(volume, 0.1 * 0.2 * 0.3, rtol=1e-6)
