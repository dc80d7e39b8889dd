"""Issue 32, class 4: a mesh link whose STEP solid would fail the STEP checks gets a checked
solid (its weld, a coarser copy, its hull) or is left out of the assembly, listed with its
reason in robot.json; the check still fails a STEP that lacks a solid robot.json does not
excuse. Meshes made for the purpose: two boxes whose union has a seam of slivers, a box with
a flat sliver piece beside it (as a Boolean of two overlapping hulls leaves), a flat mesh."""

from __future__ import annotations

import dataclasses
import json
import shutil
from pathlib import Path

import manifold3d as mf
import numpy as np
import pytest
from OCP.BRepCheck import BRepCheck_Analyzer

from simkit.check.kit import Kit
from simkit.check.readers import step as step_reader
from simkit.check.step import check_step
from simkit.derive import mesh_brep
from simkit.derive.solids import to_mesh
from simkit.emit import step
from simkit.kitio import layout
from simkit.model.robot import Mesh
from simkit.pipeline import build, model_from_spec

PLANAR = str(Path(__file__).resolve().parent / "specs" / "planar_2r.yaml")


def _two_boxes() -> Mesh:
    """Two 100 x 40 x 30 mm boxes, the second turned 1e-7 rad and raised 1e-10 m: their
    union's faces nearly coincide, so its seam is full of slivers (not a plain weld)."""
    c, s = np.cos(1e-7), np.sin(1e-7)
    turn = np.array([[1, 0, 0], [0, c, -s], [0, s, c]]) @ np.array(
        [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    )
    first = mf.Manifold.cube((0.1, 0.04, 0.03), center=True)
    second = first.transform(np.hstack([turn, [[0.05], [0.0], [1e-10]]]).tolist())
    return to_mesh(first + second)


def _with_flat_piece(mesh: Mesh) -> Mesh:
    """`mesh` plus a separate flat piece of four triangles (zero volume) beside it."""
    flat = np.array([[0.2, 0, 0], [0.21, 0, 0], [0.2, 0.01, 0], [0.21, 0.01, 0]])
    start = len(mesh.vertices)
    faces = np.array([[0, 1, 2], [2, 1, 3], [2, 1, 0], [3, 1, 2]]) + start
    return Mesh.of(np.vstack([mesh.vertices, flat]), np.vstack([mesh.faces, faces]))


def _volume_mm3(mesh: Mesh) -> float:
    return mesh_brep.signed_volume(np.asarray(mesh.vertices), np.asarray(mesh.faces)) * 1e9


def _sound(shape, mesh: Mesh) -> None:
    solids = step_reader.solids_of(shape)
    assert solids and all(BRepCheck_Analyzer(s).IsValid() for s in solids)
    held = sum(step_reader.volume(s) for s in solids)
    assert abs(held / _volume_mm3(mesh) - 1) <= mesh_brep.VOLUME_SLACK


@pytest.mark.parametrize("mesh", [_two_boxes(), _with_flat_piece(_two_boxes())])
def test_a_mesh_that_is_not_plain_gets_a_checked_solid(mesh):
    assert not mesh_brep.plain(mesh)
    plan, why = mesh_brep.mesh_plan(mesh)
    assert plan is not None and why == ""
    shape, _why = mesh_brep.mesh_shape(mesh, plan)
    _sound(shape, mesh)
    assert len(step_reader.solids_of(shape)) == 1  # the flat piece is no solid


def test_a_plain_mesh_is_faceted_as_it_stands():
    mesh = to_mesh(mf.Manifold.cube((0.1, 0.04, 0.03), center=True))
    assert mesh_brep.plain(mesh)
    assert mesh_brep.mesh_plan(mesh) == ((), "")
    _sound(mesh_brep.mesh_shape(mesh, ())[0], mesh)


def test_a_mesh_with_no_solid_in_it_is_left_out_with_its_reason():
    square = np.array([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0], [0.01, 0.01, 0]], float)
    flat = Mesh.of(square, np.array([[0, 1, 2], [2, 1, 3], [2, 1, 0], [3, 1, 2]]))
    plan, why = mesh_brep.mesh_plan(flat)
    assert plan is None and why.startswith("no valid STEP solid")


def _kit_with_link_2_left_out(kit_dir: Path, tmp_path: Path, listed: bool, solid: bool) -> Path:
    """A copy of the kit whose STEP lacks link_2's solid unless `solid`, and whose robot.json
    lists link_2 as left out when `listed`."""
    robot = model_from_spec(PLANAR)
    copy = tmp_path / kit_dir.name
    shutil.copytree(kit_dir, copy)
    if not solid:
        why = [{"link": "link_2", "why": "no valid STEP solid: made up for the test"}]
        products = dataclasses.replace(robot.products, step_left_out=why)
        robot = dataclasses.replace(robot, products=products)
    (copy / layout.step(robot.name)).write_bytes(step.step_bytes(robot))
    if listed:
        doc = json.loads((copy / "robot.json").read_text())
        doc["geometry"]["step"]["left_out"] = [{"link": "link_2", "why": "made up for the test"}]
        (copy / "robot.json").write_text(json.dumps(doc))
    return copy


@pytest.mark.slow
@pytest.mark.parametrize(
    ("listed", "solid", "passes"),
    [(True, False, True), (False, False, False), (True, True, False)],
)
def test_the_check_excuses_only_the_links_robot_json_lists(tmp_path, listed, solid, passes):
    kit_dir = build(PLANAR, tmp_path / "out").kit_dir
    kit = _kit_with_link_2_left_out(kit_dir, tmp_path / "copy", listed, solid)
    found = {f.check: f for f in check_step(Kit.open(kit))}
    assert found["step.products"].ok is passes
    assert found["step.brepcheck"].ok and found["step.volume"].ok


def test_robot_json_and_the_readme_list_a_left_out_link():
    from simkit.emit import docs, robot_json

    robot = model_from_spec(PLANAR)
    assert "left_out" not in robot_json.step_geometry(robot)  # none: the seed kits' bytes
    why = [{"link": "link_2", "why": "no valid STEP solid: made up for the test"}]
    robot = dataclasses.replace(
        robot, products=dataclasses.replace(robot.products, step_left_out=why)
    )
    assert robot_json.step_geometry(robot)["left_out"] == why
    readme = docs.emit(robot)[layout.README].decode()
    assert "Left out of the STEP assembly: `link_2` (no valid STEP solid: made up" in readme
    text = step.step_bytes(robot).decode()
    assert "PRODUCT('link_1','link_1'" in text and "PRODUCT('link_2'" not in text
