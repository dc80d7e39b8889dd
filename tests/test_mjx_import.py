"""Imported robots get a GPU scene too (issue 30), checked as the seed kits' are. Two classes
of input, as small handwritten URDFs:

- an arm whose collision geometry is dense meshes: the scene's colliders are the kit's convex
  pieces with their hulls capped at `MAX_HULL_VERTICES` vertices;
- a floating biped on box feet with cylinder legs: floor pairs for every collider, and the
  legs' cylinders meet the feet's boxes through their stand-in boxes.
"""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import mujoco
import pytest
import trimesh

from simkit.derive.gpu_colliders import MAX_HULL_VERTICES
from simkit.importer import import_robot
from simkit.pipeline import build

REPO = Path(__file__).resolve().parents[1]
#: slow (imports and builds two kits); MJX runs in a subprocess, so JAX never loads here
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(
        importlib.util.find_spec("mujoco.mjx") is None, reason="mujoco-mjx not installed"
    ),
]

INERTIAL = (
    '<inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
)


def _link(name: str, geometry: str, xyz: str = "0 0 0", mass: float = 1.0) -> str:
    placed = f'<origin xyz="{xyz}"/><geometry>{geometry}</geometry>'
    return (
        f'<link name="{name}">{INERTIAL.format(xyz=xyz, mass=mass)}'
        f"<visual>{placed}</visual><collision>{placed}</collision></link>"
    )


def _joint(name: str, parent: str, child: str, xyz: str, axis: str, limit: float = 1.5) -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
        f'<limit lower="-{limit}" upper="{limit}" effort="80" velocity="2"/></joint>'
    )


def _mesh_arm(folder: Path) -> Path:
    """A base and two links, each a 64-sided cylinder mesh (128 vertices)."""
    tube = trimesh.creation.cylinder(radius=0.04, height=0.3, sections=64)
    tube.apply_translation((0, 0, 0.15))
    tube.export(folder / "tube.stl")
    mesh = '<mesh filename="tube.stl"/>'
    text = (
        '<robot name="mesh_arm">'
        + _link("base", mesh, mass=3.0)
        + _link("upper", mesh)
        + _link("fore", mesh, mass=0.5)
        + _joint("shoulder", "base", "upper", "0 0.09 0.3", "0 1 0")
        + _joint("elbow", "upper", "fore", "0 -0.09 0.3", "0 1 0", 2.5)
        + "</robot>"
    )
    (folder / "mesh_arm.urdf").write_text(text)
    return folder / "mesh_arm.urdf"


def _biped(folder: Path) -> Path:
    """A box body on cylinder legs ending in box feet."""
    leg = '<cylinder radius="0.03" length="0.4"/>'
    foot = '<box size="0.16 0.08 0.03"/>'
    text = (
        '<robot name="box_biped">'
        + _link("body", '<box size="0.3 0.3 0.1"/>', mass=4.0)
        + _link("left_leg", leg, "0 0 -0.2")
        + _link("right_leg", leg, "0 0 -0.2")
        + _link("left_foot", foot, "0.03 0 -0.015", 0.3)
        + _link("right_foot", foot, "0.03 0 -0.015", 0.3)
        + _joint("left_hip", "body", "left_leg", "0 0.1 -0.05", "0 1 0", 0.6)
        + _joint("right_hip", "body", "right_leg", "0 -0.1 -0.05", "0 1 0", 0.6)
        + _joint("left_ankle", "left_leg", "left_foot", "0 0 -0.4", "0 1 0", 0.4)
        + _joint("right_ankle", "right_leg", "right_foot", "0 0 -0.4", "0 1 0", 0.4)
        + "</robot>"
    )
    (folder / "box_biped.urdf").write_text(text)
    return folder / "box_biped.urdf"


@pytest.fixture(scope="module")
def kits(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("gpu_import")
    out = {}
    for name, make, floating in (("mesh_arm", _mesh_arm, False), ("box_biped", _biped, True)):
        done = import_robot(make(folder), folder / f"{name}_spec", floating=floating)
        out[name] = build(str(done.spec_path), folder / "kits").kit_dir
    return out


@pytest.fixture(scope="module")
def probes(kits) -> dict[str, dict]:
    done = subprocess.run(
        [
            sys.executable,
            str(REPO / "scripts" / "bench_gpu.py"),
            "--probe",
            *map(str, kits.values()),
        ],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    rows = [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]
    return {row["kit"].removesuffix("_description"): row for row in rows}


def _scene(kit: Path):
    doc = json.loads((kit / "robot.json").read_text())
    return doc["gpu_scene"], mujoco.MjModel.from_xml_path(str(kit / doc["files"]["mjcf_mjx"]))


def test_dense_mesh_pieces_are_capped(kits, probes):
    """Every collider is a mesh piece whose hull MuJoCo caps at MAX_HULL_VERTICES (compiled
    with the colliders switched on, so MuJoCo builds their hulls)."""
    stated, _model = _scene(kits["mesh_arm"])
    spec = mujoco.MjSpec.from_file(str(kits["mesh_arm"] / "mjcf" / "mesh_arm_mjx.xml"))
    colliders = [g for g in spec.geoms if "_collision" in g.name]
    assert colliders and all(g.type == mujoco.mjtGeom.mjGEOM_MESH for g in colliders)
    for geom in colliders:
        geom.contype = 1
    model = spec.compile()
    for geom in colliders:
        mesh = model.geom(geom.name).dataid[0]
        assert model.mesh_vertnum[mesh] > MAX_HULL_VERTICES  # the piece itself is dense
        assert model.mesh_graph[model.mesh_graphadr[mesh]] <= MAX_HULL_VERTICES  # its hull
    row = probes["mesh_arm"]
    assert not row["nan"] and row["contact_slots"] <= stated["contact_slots"]


def test_a_floating_biped_meets_the_floor_with_every_collider(kits, probes):
    stated, model = _scene(kits["box_biped"])
    # every collider may meet the floor (the feet stand on it; the body lands on it in a fall)
    assert {"left_foot_collision", "right_foot_collision", "body_collision"} <= set(
        stated["floor_pairs"]
    )
    names = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) for g in model.pair_geom2}
    assert {"left_foot_collision", "right_foot_collision"} <= names
    row = probes["box_biped"]
    assert not row["nan"] and row["contact_slots"] <= stated["contact_slots"], row
