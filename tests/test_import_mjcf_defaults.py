"""MJCF import: MuJoCo resolves defaults, classes, childclass, includes, meshdir, mesh scale
and angle units (issue 31); the spec holds the compiled values."""

from __future__ import annotations

import math
import struct

import pytest

from mjcf_models import INERTIAL, joints, spec_of, write


def _stl(path, size: float) -> None:
    """A binary STL box of edge `size` (m), centred at the origin."""
    h = size / 2
    corners = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]  # fmt: skip
    data = b"\0" * 80 + struct.pack("<I", len(faces))
    for face in faces:
        data += struct.pack("<3f", 0, 0, 0)
        for i in face:
            data += struct.pack("<3f", *corners[i])
        data += b"\0\0"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)


MODEL = """<mujoco model="classes">
  <compiler angle="degree" meshdir="assets"/>
  <default>
    <default class="arm">
      <joint axis="0 0 1" range="-90 90" damping="0.5"/>
      <default class="visual"><geom contype="0" conaffinity="0" group="1"/></default>
    </default>
  </default>
  <asset><mesh name="cube" file="cube.stl" scale="2 2 2"/></asset>
  <worldbody>
    <body name="base">
      <geom type="box" size="0.05 0.05 0.05"/>
      <include file="parts/link.xml"/>
    </body>
  </worldbody>
</mujoco>
"""
LINK = f"""<mujoco>
  <body name="link1" pos="0 0 0.1" childclass="arm">
    <joint name="j1"/>{INERTIAL}
    <geom class="visual" type="mesh" mesh="cube"/>
    <geom type="box" size="0.02 0.02 0.05"/>
  </body>
</mujoco>
"""


@pytest.fixture(scope="module")
def spec(tmp_path_factory):
    folder = tmp_path_factory.mktemp("classes")
    _stl(folder / "assets" / "cube.stl", 0.05)
    write(folder / "parts", LINK, "link.xml")
    return spec_of(write(folder, MODEL), folder / "out")


def test_classes_childclass_and_degrees_resolve_as_mujoco_does(spec):
    j1 = joints(spec)["j1"]
    assert j1["type"] == "revolute" and j1["axis"] == [0.0, 0.0, 1.0]
    assert j1["lower"] == pytest.approx(-math.pi / 2) and j1["upper"] == pytest.approx(math.pi / 2)
    assert j1["damping"] == pytest.approx(0.5)


def test_included_body_and_scaled_mesh_become_the_links_solid_and_collision(spec):
    link = next(x for x in spec["links"] if x["name"] == "link1")
    assert link["mass"] == pytest.approx(1.0)
    assert [s["shape"] for s in link["collision_primitives"]] == ["box"]  # contype 0: visual
    assert link["solid"] == [{"shape": "mesh", "file": "meshes/cube.stl"}]


def test_the_source_and_its_files_are_kept_with_digests(spec, tmp_path_factory):
    source = spec["source"]
    assert source["file"] == "classes.source.xml"  # named by <mujoco model="classes">
    assert set(source["assets"]) == {"parts/link.xml", "assets/cube.stl"}


def test_the_kit_is_named_by_the_model_attribute(tmp_path):
    """Robot collections name every model file `robot.xml`: the kit takes `<mujoco model>`,
    and the file name where the model has none."""
    from pathlib import Path

    from simkit.importer import robot_name

    named = tmp_path / "robot.xml"
    named.write_text('<!-- a collection --><mujoco model="Two-Link Arm"><worldbody/></mujoco>')
    assert robot_name(named) == "two_link_arm"
    unnamed = tmp_path / "my_arm.xml"
    unnamed.write_text("<mujoco><worldbody/></mujoco>")
    assert robot_name(unnamed) == "my_arm"
    assert robot_name(Path(tmp_path / "absent.urdf")) == "absent"
