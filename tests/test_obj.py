"""kitio/obj.py: the OBJ collision pieces are deterministic text through the one number
formatter, read back exactly (float32, as the STL stored them), and MuJoCo reads them."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from simkit.kitio.fmt import num
from simkit.kitio.obj import from_obj, read_mesh, to_obj
from simkit.kitio.stl import to_stl
from simkit.model.robot import Mesh

#: A unit-ish tetrahedron with coordinates that are not float32-exact.
TETRA = Mesh.of(
    np.array([[0.0, 0.0, 0.0], [0.1234567891234, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 1 / 3]]),
    np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
)


def test_obj_is_deterministic_text_through_fmt_num():
    data = to_obj(TETRA, "link_1_00")
    assert data == to_obj(TETRA, "link_1_00")
    lines = data.decode("ascii").splitlines()
    assert lines[:2] == ["# simkit link_1_00", "o link_1_00"]
    vertices = [line.split()[1:] for line in lines if line.startswith("v ")]
    assert len(vertices) == 4
    assert all(token == num(float(token)) for row in vertices for token in row)
    assert next(line for line in lines if line.startswith("f ")) == "f 1 3 2"


def test_obj_reads_back_the_float32_vertices_the_stl_held():
    mesh = from_obj(to_obj(TETRA, "t"))
    assert np.array_equal(mesh.faces, TETRA.faces)
    assert np.array_equal(mesh.vertices.astype(np.float32), TETRA.vertices.astype(np.float32))
    stl = read_mesh("t.stl", to_stl(TETRA, "t"))
    assert sorted(map(tuple, stl.vertices.astype(np.float32))) == sorted(
        map(tuple, mesh.vertices.astype(np.float32))
    )
    assert read_mesh("t.obj", to_obj(TETRA, "t")).vertices.shape == (4, 3)


def test_obj_reader_takes_polygons_slashes_and_negative_indices():
    text = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1 -1//1\n"
    mesh = from_obj(text)
    assert mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    with pytest.raises(ValueError, match="vertex"):
        from_obj(b"v 0 0 0\nv 1 0 0\nf 1 2 7\n")


def test_mujoco_reads_the_obj_piece():
    xml = """<mujoco><asset><mesh name="m" file="piece.obj"/></asset>
    <worldbody><body><freejoint/><geom type="mesh" mesh="m"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml, {"piece.obj": to_obj(TETRA, "piece")})
    assert model.mesh_vertnum[0] == 4
    assert model.geom_rbound[0] > 0.1
