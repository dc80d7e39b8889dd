"""Issue 25: Drake loads a kit whose collision is the visual solid's convex hull.

Links whose collision is the visual (`simkit import --hull`, a URDF without `<collision>` on a
floating base, a spec's `collision: mesh`) get that hull as one OBJ collision piece like any
other link, so the URDF and SDF never point a collision at the visual STL (Drake's SceneGraph
takes convex hulls only from OBJ, VTK or glTF). Small purpose-written inputs; one
example-robot-data robot where installed. Drake (the `drake` wheel, a test extra) is needed by
the slow tests only.
"""

from __future__ import annotations

import importlib.util
import json
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import trimesh

import corpus_pick
from drake_load import load_kit
from simkit.importer import import_robot
from simkit.kitio.cache import Cache
from simkit.kitio.obj import from_obj
from simkit.kitio.stl import from_stl
from simkit.pipeline import build, model_from_spec

#: the kit-building Drake tests are skipped where the test extra's drake is missing
needs_drake = pytest.mark.skipif(
    importlib.util.find_spec("pydrake") is None,
    reason="drake is not installed (pip install -e .[test])",
)


def _proximity_geometries(kit: Path, fmt: str) -> tuple[int, int]:
    """(SceneGraph proximity geometries, `<collision>` elements) of the kit's URDF or SDF,
    loaded into a MultibodyPlant with SceneGraph (the fixed URDF root welded to the world)."""
    from pydrake.geometry import Role

    _plant, _instance, _context, inspector, path = load_kit(kit, fmt)
    return inspector.NumGeometriesWithRole(Role.kProximity), path.read_text().count("<collision ")


def _collision_files(kit: Path) -> list[str]:
    """Every mesh file a `<collision>` of the URDF or SDF names."""
    doc = json.loads((kit / "robot.json").read_text())
    files = []
    urdf = ET.parse(kit / "urdf" / f"{doc['name']}.urdf").getroot()
    files += [m.get("filename") for c in urdf.iter("collision") for m in c.iter("mesh")]
    sdf = ET.parse(kit / "sdf" / f"{doc['name']}.sdf").getroot()
    files += [u.text for c in sdf.iter("collision") for u in c.iter("uri")]
    return files


def _assert_drake_loads(kit: Path, hull_links: list[str]) -> None:
    """Drake loads URDF and SDF with geometry; every collision mesh is OBJ; each hull link's
    single piece is its visual mesh's convex hull."""
    for fmt in ("urdf", "sdf"):
        found, collisions = _proximity_geometries(kit, fmt)
        assert found == collisions > 0, (fmt, found, collisions)
    files = _collision_files(kit)
    assert files and all(f.endswith(".obj") for f in files), files
    doc = json.loads((kit / "robot.json").read_text())
    links = {link["name"]: link for link in doc["links"]}
    for name in hull_links:
        (piece,) = links[name]["mesh"]["collision"]
        visual = from_stl((kit / links[name]["mesh"]["visual"]).read_bytes())
        hull = from_obj((kit / piece).read_bytes())
        got = trimesh.Trimesh(hull.vertices, hull.faces)
        want = trimesh.Trimesh(visual.vertices, visual.faces).convex_hull
        assert got.is_watertight and got.is_convex
        assert got.volume == pytest.approx(want.volume, rel=1e-6)


def _write_stl(path: Path, mesh) -> str:
    path.parent.mkdir(parents=True, exist_ok=True)
    mesh.export(path)
    return path.name


def _hull_urdf(tmp_path: Path) -> Path:
    """A 2-link arm: visual meshes that are not convex (a tube, two boxes 1 cm apart) and
    separate collision meshes (so the importer would keep them as `given` without --hull)."""
    meshes = tmp_path / "src" / "meshes"
    tube = trimesh.creation.annulus(r_min=0.03, r_max=0.05, height=0.1)
    ell = trimesh.util.concatenate(
        [
            trimesh.creation.box(
                (0.3, 0.04, 0.04), trimesh.transformations.translation_matrix((0.15, 0, 0))
            ),
            trimesh.creation.box(
                (0.04, 0.04, 0.2), trimesh.transformations.translation_matrix((0.33, 0, 0.1))
            ),
        ]
    )
    for name, mesh in (("tube", tube), ("ell", ell)):
        _write_stl(meshes / f"{name}.stl", mesh)
        _write_stl(meshes / f"{name}_col.stl", mesh.convex_hull)

    def link(name: str, mesh: str, mass: float) -> str:
        return (
            f'<link name="{name}"><inertial><mass value="{mass}"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
            f'<visual><geometry><mesh filename="../meshes/{mesh}.stl"/></geometry></visual>'
            f'<collision><geometry><mesh filename="../meshes/{mesh}_col.stl"/></geometry>'
            "</collision></link>"
        )

    urdf = tmp_path / "src" / "urdf" / "hullarm.urdf"
    urdf.parent.mkdir(parents=True)
    urdf.write_text(
        '<robot name="hullarm">'
        + link("base_link", "tube", 2.0)
        + link("arm", "ell", 1.0)
        + '<joint name="shoulder" type="revolute"><parent link="base_link"/>'
        '<child link="arm"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>'
        '<limit lower="-1.5" upper="1.5" effort="20" velocity="2"/></joint></robot>',
        encoding="utf-8",
    )
    return urdf


@pytest.mark.slow
@needs_drake
def test_imported_with_hull_loads_in_drake(tmp_path):
    done = import_robot(_hull_urdf(tmp_path), tmp_path / "spec", hull_collision=True)
    text = done.spec_path.read_text()
    assert text.count("collision: mesh") == 2  # both links collide with their visual hull
    built = build(str(done.spec_path), tmp_path / "kits", step=False)
    _assert_drake_loads(built.kit_dir, ["base_link", "arm"])


SPEC = """\
name: visual_hull
title: Visual hull
root: world
seed: 3
poses_deg:
  home: [0]
links:
  - name: base_link
    mass: 2.0
    solid:
      - {shape: box, size: [0.2, 0.2, 0.04], xyz: [0, 0, 0.02]}
    collision: convex
  - name: arm
    mass: 0.8
    collision: mesh
    solid:
      - {shape: cylinder, radius: 0.04, from: [0, -0.02, 0], to: [0, 0.02, 0]}
      - {shape: cylinder, radius: 0.025, from: [0, -0.03, 0], to: [0, 0.03, 0], subtract: true}
      - {shape: box, size: [0.25, 0.03, 0.03], xyz: [0.16, 0, 0]}
joints:
  - name: base_joint
    type: fixed
    parent: world
    child: base_link
  - name: hinge
    parent: base_link
    child: arm
    xyz: [0, 0, 0.1]
    axis: [0, 1, 0]
    lower_deg: -90
    upper_deg: 90
    effort_peak: 10
    max_velocity_deg_s: 90
"""


def test_collision_mesh_link_gets_its_hull_as_one_piece(tmp_path):
    """The derive step alone (fast): the `mesh` link's one piece is its solid's convex hull,
    holding every vertex of the solid; the `convex` link keeps its exact piece."""
    from scipy.spatial import ConvexHull

    spec = tmp_path / "visual_hull.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    robot = model_from_spec(str(spec), cache=Cache.disabled())
    arm = robot.link("arm")
    (piece,) = arm.collision
    hull = ConvexHull(piece.vertices)
    assert hull.volume == pytest.approx(ConvexHull(arm.solid.vertices).volume, rel=1e-9)
    inside = arm.solid.vertices @ hull.equations[:, :3].T + hull.equations[:, 3]
    assert inside.max() <= 1e-9
    assert arm.collision_report["pieces"] == 1 and arm.collision_report["coverage"] == 1.0
    assert len(robot.link("base_link").collision) == 1


@pytest.mark.slow
@needs_drake
def test_spec_collision_mesh_loads_in_drake(tmp_path):
    """A spec link whose collision is its visual (`collision: mesh`), next to a `convex` one."""
    spec = tmp_path / "visual_hull.yaml"
    spec.write_text(SPEC, encoding="utf-8")
    built = build(str(spec), tmp_path / "kits", step=False)
    _assert_drake_loads(built.kit_dir, ["arm"])
    doc = json.loads((built.kit_dir / "robot.json").read_text())
    methods = {g["name"]: g["collision"] for g in doc["geometry"]["links"]}
    assert methods["arm"]["method"] == "mesh" and methods["arm"]["pieces"] == 1
    assert methods["arm"]["coverage"] == pytest.approx(1.0)


def _hull_arm(robot) -> bool:
    """Collision meshes, and movable joints that are all continuous."""
    types = corpus_pick.movable(robot)
    return bool(corpus_pick.meshes(robot, "collision")) and set(types) == {"continuous"}


@pytest.mark.slow
@needs_drake
def test_example_robot_imported_with_hull_loads_in_drake(tmp_path):
    """A small example-robot-data arm on continuous joints whose URDF has collision meshes
    (the smallest such URDF, corpus_pick.py), imported with --hull."""
    source = corpus_pick.pick(_hull_arm)
    done = import_robot(source, tmp_path / "spec", name="pendulum", hull_collision=True)
    built = build(str(done.spec_path), tmp_path / "kits", step=False)
    doc = json.loads((built.kit_dir / "robot.json").read_text())
    hull_links = [
        g["name"] for g in doc["geometry"]["links"] if g["collision"].get("method") == "mesh"
    ]
    assert hull_links
    _assert_drake_loads(built.kit_dir, hull_links)
    assert np.isfinite([g["collision"]["coverage"] for g in doc["geometry"]["links"]]).all()
