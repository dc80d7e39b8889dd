"""Issue 42, class 6: an imported link with two visuals (a body and a ring standing 0.06 mm
proud of it) and one collision, the body alone. The source's collision is what it is: for an
imported kit (robot.json has a `source` block) `collision.cover` measures what the source's
own (`given`) collision leaves out and reports it in one line, never failing for it. A spec
robot (no `source` block) keeps the strict rule. The kit's piece is replaced here by the
body's hull, as a source that is not grown would give it."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from simkit.check.geometry import COVER_TOL, check_collision
from simkit.check.kit import Kit
from simkit.importer import import_robot
from simkit.kitio.obj import to_obj
from simkit.model.robot import Mesh
from simkit.pipeline import build

PROUD = 6e-5  # m: how far the ring stands out of the body

INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0"'
    ' iyz="0"/></inertial>'
)
URDF = f"""<robot name="ringed">
  <link name="base">{INERTIAL}
    <visual><geometry><box size="0.1 0.1 0.02"/></geometry></visual>
    <collision><geometry><box size="0.1 0.1 0.02"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <link name="arm">{INERTIAL}
    <visual><geometry><mesh filename="body.stl"/></geometry></visual>
    <visual><geometry><mesh filename="ring.stl"/></geometry></visual>
    <collision><geometry><mesh filename="body.stl"/></geometry></collision></link>
</robot>
"""


def _body() -> trimesh.Trimesh:
    return trimesh.creation.cylinder(radius=0.04, height=0.1, sections=32)


@pytest.fixture(scope="module")
def kit(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("ringed")
    source = root / "src"
    source.mkdir()
    ring = trimesh.creation.annulus(r_min=0.038, r_max=0.04 + PROUD, height=0.005, sections=32)
    (source / "body.stl").write_bytes(_body().export(file_type="stl"))
    (source / "ring.stl").write_bytes(ring.export(file_type="stl"))
    (source / "ringed.urdf").write_text(URDF)
    spec = import_robot(source / "ringed.urdf", root / "spec").spec_path
    return build(str(spec), root / "kits").kit_dir


def _as_the_source_gave(kit: Path, tmp_path: Path, imported: bool) -> Path:
    """A copy whose arm piece is the body's hull (the ring sticks out), with or without
    robot.json's `source` block."""
    copy = Path(shutil.copytree(kit, tmp_path / kit.name))
    doc = json.loads((copy / "robot.json").read_text())
    arm = next(link for link in doc["links"] if link["name"] == "arm")
    assert len(arm["mesh"]["collision"]) == 1
    hull = _body().convex_hull
    piece = Mesh.of(np.asarray(hull.vertices, float), np.asarray(hull.faces))
    (copy / arm["mesh"]["collision"][0]).write_bytes(to_obj(piece, "arm"))
    if not imported:
        doc.pop("source")
        (copy / "robot.json").write_text(json.dumps(doc))
    return copy


def _cover(kit: Path):
    return next(f for f in check_collision(Kit.open(kit)) if f.check == "collision.cover")


@pytest.mark.slow
def test_the_built_kit_covers_its_visual(kit):
    assert _cover(kit).ok


@pytest.mark.slow
def test_an_imported_kit_reports_what_the_sources_collision_leaves_out(kit, tmp_path):
    found = _cover(_as_the_source_gave(kit, tmp_path, imported=True))
    assert found.ok, found.line()
    assert "reported as given: arm" in found.detail and "\n" not in found.detail
    worst = float(found.detail.split("up to ")[1].split(" m")[0])
    assert COVER_TOL < worst < 2 * PROUD


@pytest.mark.slow
def test_a_spec_robot_keeps_the_strict_rule(kit, tmp_path):
    found = _cover(_as_the_source_gave(kit, tmp_path, imported=False))
    assert not found.ok and "reported as given" not in found.detail
