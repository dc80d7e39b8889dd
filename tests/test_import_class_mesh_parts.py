"""Issue 42, class 10: a visual mesh made of several closed parts (a glTF or CAD scene
flattened to one mesh) that overlap, or of which one is wound inside out. The link's solid is
the union of its parts (derive/solids.py `union_of_parts`), so the visual STL, the STEP solid
and the STEP check agree on one volume; before, the STL counted an overlap twice and an
inside-out part as negative volume, and the STEP was 210 % off it here."""

from __future__ import annotations

import json
from pathlib import Path

import manifold3d as mf
import numpy as np
import pytest
import trimesh

from simkit.derive.solids import union_of_parts
from simkit.importer import import_robot
from simkit.kitio.stl import from_stl
from simkit.pipeline import build

#: m^3: a 100 mm cube beside an 80 mm cube, overlapping by 30 x 80 x 80 mm
UNION = 1e-3 + 0.08**3 - 0.03 * 0.08 * 0.08


def _parts(inside_out: bool) -> list[trimesh.Trimesh]:
    first = trimesh.creation.box((0.1, 0.1, 0.1))
    second = trimesh.creation.box((0.08, 0.08, 0.08))
    second.apply_translation((0.06, 0.0, 0.0))
    if inside_out:
        second.invert()
    return [first, second]


def _manifold(parts: list[trimesh.Trimesh]) -> mf.Manifold:
    mesh = trimesh.util.concatenate(parts)
    return mf.Manifold(
        mf.Mesh(
            vert_properties=np.asarray(mesh.vertices, np.float32),
            tri_verts=np.asarray(mesh.faces, np.uint32),
        )
    )


@pytest.mark.parametrize("inside_out", [False, True])
def test_overlapping_or_inside_out_parts_become_their_union(inside_out):
    solid = _manifold(_parts(inside_out))
    assert abs(solid.volume() - UNION) > 1e-4  # as read: the overlap twice, or minus a part
    united = union_of_parts(solid)
    assert united.status() == mf.Error.NoError
    assert united.volume() == pytest.approx(UNION, rel=1e-6)
    assert len(united.decompose()) == 1


def test_a_cavity_stays_a_cavity_and_disjoint_parts_are_kept_as_read():
    hollow = trimesh.creation.box((0.1, 0.1, 0.1))
    cavity = trimesh.creation.box((0.05, 0.05, 0.05))
    cavity.invert()
    bolt = trimesh.creation.box((0.01, 0.01, 0.01))
    bolt.apply_translation((0.2, 0.0, 0.0))
    solid = _manifold([hollow, cavity, bolt])
    assert union_of_parts(solid) is solid  # nothing to unite: the same bytes as before
    assert solid.volume() == pytest.approx(1e-3 - 0.05**3 + 1e-6, rel=1e-6)


def one_mesh_urdf(name: str, mesh_file: str) -> str:
    """A two-link URDF whose base's visual is `mesh_file` (beside it) and whose tip is a box."""
    return f"""<robot name="{name}">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="{mesh_file}"/></geometry></visual></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="tip"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <link name="tip"><inertial><mass value="0.5"/><inertia ixx="0.001" iyy="0.001" izz="0.001"
    ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.05 0.05 0.05"/></geometry></visual></link>
</robot>
"""


URDF = one_mesh_urdf("parts", "parts.obj")


@pytest.mark.slow
def test_a_link_of_inside_out_overlapping_parts_builds_with_its_step_solid(tmp_path: Path):
    source = tmp_path / "src"
    source.mkdir()
    obj = trimesh.util.concatenate(_parts(inside_out=True)).export(file_type="obj")
    (source / "parts.obj").write_text(obj)
    (source / "parts.urdf").write_text(URDF)
    spec = import_robot(source / "parts.urdf", tmp_path / "spec").spec_path
    kit = build(str(spec), tmp_path / "kits").kit_dir  # CheckFailed on step.volume before
    stl = from_stl((kit / "meshes" / "visual" / "base.stl").read_bytes())
    tri = stl.vertices[stl.faces]
    volume = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6
    assert volume == pytest.approx(UNION, rel=1e-5)
    assert "left_out" not in json.loads((kit / "robot.json").read_text())["geometry"]["step"]
