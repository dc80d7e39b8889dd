"""The import's STEP budget counts every triangle the STEP will hold (issue 32, class 3): a
link whose solid holds a mesh is faceted whole, so its spheres and cylinders count as the
triangles derive makes of them; a STEP over the budget is left out before the build, with
one line."""

from __future__ import annotations

import trimesh
import yaml

from simkit.derive.solids import primitive_solid
from simkit.importer import import_robot
from simkit.importer.fixups.step_budget import FACETED, MAX_TRIANGLES
from simkit.model.robot import Shape


def test_the_counts_are_derives_own():
    at = {"xyz": (0.0, 0.0, 0.0), "rpy": (0.0, 0.0, 0.0)}
    shapes = {
        "box": Shape(kind="box", size=(0.1, 0.2, 0.3), **at),
        "cylinder": Shape(kind="cylinder", radius=0.05, length=0.2, **at),
        "cone": Shape(kind="cone", radius=0.05, radius_top=0.02, length=0.2, **at),
        "capsule": Shape(kind="capsule", radius=0.05, length=0.2, **at),
        "sphere": Shape(kind="sphere", radius=0.05, **at),
    }
    made = {k: len(primitive_solid(s).to_mesh().tri_verts) for k, s in shapes.items()}
    assert made == FACETED


def _link(name: str, spheres: int) -> str:
    visuals = '<visual><geometry><mesh filename="part.stl"/></geometry></visual>'
    visuals += "".join(
        f'<visual><origin xyz="0 0 {0.1 * (k + 1)}"/><geometry><sphere radius="0.03"/>'
        "</geometry></visual>"
        for k in range(spheres)
    )
    return (
        f'<link name="{name}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" '
        f'izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>{visuals}</link>'
    )


def test_spheres_beside_a_mesh_count_toward_the_budget(tmp_path):
    trimesh.creation.box((0.05, 0.05, 0.05)).export(tmp_path / "part.stl")  # 12 triangles
    spheres = MAX_TRIANGLES // FACETED["sphere"] + 1  # 5 spheres: 23,040 faceted triangles
    joint = (
        '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1"/></joint>'
    )
    body = _link("base", 0) + _link("arm", spheres) + joint
    (tmp_path / "r.urdf").write_text(f'<?xml version="1.0"?><robot name="r">{body}</robot>')
    done = import_robot(tmp_path / "r.urdf", tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert spec["step"] is False
    said = [line for line in done.lines if "no STEP assembly" in line]
    expected = 12 * 2 + spheres * FACETED["sphere"]
    assert len(said) == 1 and f"hold {expected:,} triangles" in said[0], said
