"""Issue 42, class 5: a thin plate (508 x 383 x 6.6 mm) whose STL is four overlapping boxes,
watertight but wound inconsistently. The importer rewinds it body by body and one body comes
out inside out; the link's solid is the union of the four bodies turned outward
(derive/solids.py `union_of_parts`), so the visual STL holds the plate's volume and the STEP
check passes (before: the STL held half of it and `step.volume` was 100 % off)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh
from tests.test_import_class_mesh_parts import one_mesh_urdf

from simkit.derive.solids import link_solid
from simkit.importer import import_robot
from simkit.model.robot import Shape
from simkit.pipeline import build

WIDTH, DEPTH, THICK = 0.508, 0.383, 0.0066  # m
OVERLAP = 0.01  # m: the four quarters overlap by this much at the middle

URDF = one_mesh_urdf("plate", "plate.stl")


def _plate() -> trimesh.Trimesh:
    """Four overlapping quarter boxes in one mesh, every fifth triangle turned over."""
    quarters = []
    for i in (-0.5, 0.5):
        for j in (-0.5, 0.5):
            box = trimesh.creation.box((WIDTH / 2 + OVERLAP / 2, DEPTH / 2 + OVERLAP / 2, THICK))
            box.apply_translation((i * (WIDTH / 2 - OVERLAP / 2), j * (DEPTH / 2 - OVERLAP / 2), 0))
            quarters.append(box)
    mesh = trimesh.util.concatenate(quarters)
    faces = np.array(mesh.faces)
    faces[::5] = faces[::5, ::-1]
    return trimesh.Trimesh(mesh.vertices, faces, process=False)


def _imported(tmp_path: Path) -> Path:
    plate = _plate()
    assert plate.is_watertight and not plate.is_winding_consistent
    assert len(plate.split(only_watertight=False)) == 4
    source = tmp_path / "src"
    source.mkdir()
    (source / "plate.stl").write_bytes(plate.export(file_type="stl"))
    (source / "plate.urdf").write_text(URDF)
    return import_robot(source / "plate.urdf", tmp_path / "spec").spec_path


def _volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    tri = np.asarray(vertices)[np.asarray(faces)]
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6)


def test_the_plates_solid_holds_the_plate(tmp_path):
    spec = _imported(tmp_path)
    stl = next((spec.parent / "meshes").glob("*.stl"))
    shape = Shape(
        "mesh", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), file=stl.relative_to(spec.parent).as_posix()
    )
    solid = link_solid((shape,), spec.parent)
    assert _volume(solid.vertices, solid.faces) == pytest.approx(WIDTH * DEPTH * THICK, rel=1e-5)


@pytest.mark.slow
def test_the_plate_builds_with_a_step_solid_within_tolerance(tmp_path):
    kit = build(str(_imported(tmp_path)), tmp_path / "kits").kit_dir  # CheckFailed before
    assert (kit / "step").is_dir()
