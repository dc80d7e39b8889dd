"""CAD meshes that Open CASCADE could not make a valid STEP solid of (derive/brep.py,
derive/shellfix.py): a T-junction closed by a zero-area needle, and a zero-thickness fin or
two solids pinched along one edge, which leave an edge on four triangles. Before the repair
the needle's face was dropped and BRepCheck refused the link's solid (step.brepcheck)."""

from __future__ import annotations

import numpy as np
import pytest

from simkit.derive.brep import mesh_solid
from simkit.derive.shellfix import over_shared, unpinched, without_needles
from simkit.model.robot import Mesh


def cube_with_needle() -> tuple[np.ndarray, np.ndarray]:
    """A 20 mm cube (m) whose first triangle's longest edge a-b carries a vertex at its
    midpoint: the triangle is split there and the T-junction is closed by the zero-area
    needle a-b-m, so every edge has two triangles, as CAD exporters write it."""
    import trimesh

    cube = trimesh.creation.box((0.02, 0.02, 0.02))
    vertices, faces = np.array(cube.vertices), [list(t) for t in cube.faces]
    turns = [faces[0][i:] + faces[0][:i] for i in range(3)]
    a, b, c = max(turns, key=lambda t: np.linalg.norm(vertices[t[1]] - vertices[t[0]]))
    m = len(vertices)
    vertices = np.vstack([vertices, (vertices[a] + vertices[b]) / 2])
    faces[0] = [a, m, c]
    faces += [[m, b, c], [a, b, m]]
    return vertices, np.array(faces)


def faces_and_volume(shape) -> tuple[int, float, bool]:
    """Face count, volume (mm^3) and BRepCheck's verdict of an OCC shape."""
    from OCP.BRepCheck import BRepCheck_Analyzer
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    explorer, count = TopExp_Explorer(shape, TopAbs_FACE), 0
    while explorer.More():
        count += 1
        explorer.Next()
    return count, props.Mass(), BRepCheck_Analyzer(shape).IsValid()


def test_a_needle_closing_a_t_junction_gives_a_valid_solid():
    vertices, faces = cube_with_needle()
    count, volume, valid = faces_and_volume(mesh_solid(Mesh.of(vertices, faces)))
    assert valid
    assert count == len(faces)  # the needle was flipped into two real faces, none dropped
    assert volume == pytest.approx(8000.0, rel=1e-9)


def test_a_needle_is_flipped_into_the_triangle_across_its_longest_edge():
    vertices, faces = cube_with_needle()
    flipped = without_needles(vertices * 1000.0, faces, 1e-4)
    assert len(flipped) == len(faces)
    corners = vertices[flipped] * 1000.0
    areas = np.linalg.norm(
        np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1
    )
    assert areas.min() > 1.0  # mm^2: no needle left
    assert not over_shared(flipped)


def test_a_fin_on_an_edge_is_dropped_and_nothing_else():
    import trimesh

    cube = trimesh.creation.box((0.02, 0.02, 0.02))
    vertices, faces = np.array(cube.vertices), np.array(cube.faces)
    a, b = faces[0][:2]
    tip = len(vertices)
    vertices = np.vstack([vertices, vertices[a] + [0.0, 0.0, 0.05]])
    with_fin = np.vstack([faces, [[a, b, tip], [b, a, tip]]])  # two sides of one sheet
    assert over_shared(with_fin)
    _nodes, out = unpinched(vertices, with_fin)
    assert not over_shared(out)
    assert sorted(map(tuple, out)) == sorted(map(tuple, faces))


def test_two_solids_pinched_along_an_edge_are_split_by_fan():
    """Two tetrahedra that share the edge 0-1 (and nothing else): the edge has four
    triangles; each solid keeps its own copy of the edge, paired by its side."""
    vertices = np.array(
        [[0, 0, 0], [0, 0, 1], [1, 0.2, 0.5], [0.2, 1, 0.5], [-1, -0.2, 0.5], [-0.2, -1, 0.5]],
        dtype=float,
    )
    first = [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]
    second = [[0, 1, 4], [0, 4, 5], [0, 5, 1], [1, 5, 4]]
    faces = np.array(first + second)
    volumes = [
        np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum() / 6
        for t in (vertices[np.array(first)], vertices[np.array(second)])
    ]
    faces = np.array(
        [
            f if v > 0 else f[::-1]
            for part, v in ((first, volumes[0]), (second, volumes[1]))
            for f in part
        ]
    )
    assert over_shared(faces)
    nodes, out = unpinched(vertices, faces)
    assert not over_shared(out)
    assert len(nodes) == len(vertices) + 2  # one more copy of each end of the pinched edge
    assert np.allclose(nodes[out], vertices[faces])  # the same triangles, in place
