"""STEP AP214 assembly (issue 14): exact solids, deterministic bytes, and a check that fails
on a tampered file (a link moved 5 mm, a solid removed)."""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
import zipfile
from pathlib import Path

import manifold3d as mf
import numpy as np
import pytest

from simkit.check import run_checks
from simkit.check.readers import step as step_reader
from simkit.check.step import check_step, zero_pose_frames
from simkit.derive import brep
from simkit.derive.solids import to_mesh
from simkit.diff import diff_kits
from simkit.emit import step
from simkit.kitio import layout
from simkit.kitio.stepfile import canonical_tail, split
from simkit.model.robot import Shape
from simkit.pipeline import build, model_from_spec

SPECS = Path(__file__).resolve().parent / "specs"
PLANAR = str(SPECS / "planar_2r.yaml")


def _shape(kind: str, **kw) -> Shape:
    return Shape(kind=kind, xyz=kw.pop("xyz", (0.0, 0.0, 0.0)), rpy=(0.0, 0.0, 0.0), **kw)


@pytest.mark.parametrize(
    ("shape", "expected_mm3"),
    [
        (_shape("box", size=(0.01, 0.02, 0.03)), 10 * 20 * 30),
        (_shape("cylinder", radius=0.01, length=0.05), math.pi * 10**2 * 50),
        (
            _shape("cone", radius=0.01, radius_top=0.005, length=0.03),
            math.pi * 30 / 3 * (10**2 + 10 * 5 + 5**2),
        ),
        (_shape("capsule", radius=0.01, length=0.04), math.pi * 100 * 40 + 4 / 3 * math.pi * 1e3),
        (_shape("sphere", radius=0.02), 4 / 3 * math.pi * 20**3),
    ],
)
def test_primitives_are_exact_solids(shape, expected_mm3):
    from OCP.BRepCheck import BRepCheck_Analyzer

    solid = brep.primitive_shape(shape)
    assert BRepCheck_Analyzer(solid).IsValid()
    assert step_reader.volume(solid) == pytest.approx(expected_mm3, rel=1e-9)


def test_union_and_difference_and_pose():
    """A 20 mm cube with a 10 mm cube added beside it (touching) and a 5 mm bore cut through."""
    shapes = (
        _shape("box", size=(0.02, 0.02, 0.02)),
        _shape("box", size=(0.01, 0.01, 0.01), xyz=(0.015, 0.0, 0.0)),
        _shape("cylinder", radius=0.0025, length=0.03, subtract=True),
    )
    link = _link(shapes)
    solid = brep.link_shape(link)
    assert len(step_reader.solids_of(solid)) == 1
    expected = 20**3 + 10**3 - math.pi * 2.5**2 * 20
    assert step_reader.volume(solid) == pytest.approx(expected, rel=1e-9)
    np.testing.assert_allclose(
        step_reader.bounds(solid), [[-10, -10, -10], [20, 10, 10]], atol=1e-9
    )


def _link(shapes, solid=None):
    from simkit.model.robot import Link

    return Link("part", 1.0, None, None, tuple(shapes), "convex", solid=solid)


def test_mesh_link_pieces_are_separate_valid_solids_without_a_fuse():
    """manifold3d keeps two boxes that share a face as two shells, and a bolt apart from its
    part is a third: three faceted solids in one compound, each valid, the volume exact."""
    from OCP.BRepCheck import BRepCheck_Analyzer

    foot = mf.Manifold.cube((0.12, 0.08, 0.02), center=True).translate((0.06, 0, 0.01))
    wall = mf.Manifold.cube((0.02, 0.08, 0.10), center=True).translate((0.01, 0, 0.07))
    bolt = mf.Manifold.cube((0.01, 0.01, 0.01), center=True).translate((0.3, 0, 0))
    mesh = to_mesh(foot + wall + bolt)
    shape = brep.link_shape(_link([_shape("mesh", file="x.stl")], solid=mesh))
    solids = step_reader.solids_of(shape)
    assert len(solids) == 3
    assert all(BRepCheck_Analyzer(s).IsValid() for s in solids)
    expected = 120 * 80 * 20 + 20 * 80 * 100 + 10 * 10 * 10
    assert sum(step_reader.volume(s) for s in solids) == pytest.approx(expected, rel=1e-9)


def test_canonical_tail_ignores_the_writers_colour_order():
    head = "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1 = PRODUCT('a');\n#2 = PRODUCT('b');\n"
    a = (
        "#3 = STYLED_ITEM('color',(#4),#1);\n#4 = COLOUR_RGB('',1.,0.,0.);\n"
        "#5 = STYLED_ITEM('color',(#6),#2);\n#6 = COLOUR_RGB('',0.,1.,0.);\n"
    )
    b = (
        "#3 = STYLED_ITEM('color',(#4),#2);\n#4 = COLOUR_RGB('',0.,1.,0.);\n"
        "#5 = STYLED_ITEM('color',(#6),#1);\n#6 = COLOUR_RGB('',1.,0.,0.);\n"
    )
    foot = "ENDSEC;\nEND-ISO-10303-21;\n"
    first, second = canonical_tail(head + a + foot), canonical_tail(head + b + foot)
    assert first == second
    _, entities, _ = split(first)
    bodies = dict(entities)
    # meaning kept: each product still points at its own colour
    styled = {
        body.split("),#")[1].rstrip(");\n"): body for body in bodies.values() if "STYLED" in body
    }
    red = next(i for i, body in bodies.items() if "1.,0.,0." in body)
    assert f"(#{red})" in styled["1"]


def test_step_of_a_small_robot_is_deterministic_and_named():
    robot = model_from_spec(PLANAR)
    first, second = step.step_bytes(robot), step.step_bytes(robot)
    assert first == second
    text = first.decode()
    assert "FILE_SCHEMA(('AUTOMOTIVE_DESIGN" in text
    assert "SI_UNIT(.MILLI.,.METRE.)" in text
    assert "'1970-01-01T00:00:00'" in text and "Open CASCADE STEP" not in text
    for link in robot.links:
        assert f"PRODUCT('{link.name}','{link.name}'" in text


def test_zero_pose_frames_walk_fixed_and_floating_joints():
    doc = {
        "joints": [{"parent": "a", "child": "b", "origin_xyz": [0, 0, 1], "origin_rpy": [0, 0, 0]}],
        "fixed_joints": [
            {"parent": "world", "child": "a", "origin_xyz": [1, 0, 0], "origin_rpy": [0, 0, 0]}
        ],
    }
    poses = zero_pose_frames(doc, "a")
    np.testing.assert_allclose(poses["world"][:3, 3], [-1, 0, 0])
    np.testing.assert_allclose(poses["b"][:3, 3], [0, 0, 1])


# --- kit-building tests -----------------------------------------------------------------


def _tampered(kit_dir: Path, tmp_path: Path, robot) -> Path:
    """A copy of the kit whose STEP is rewritten from `robot`."""
    copy = tmp_path / kit_dir.name
    shutil.copytree(kit_dir, copy)
    (copy / layout.step(robot.name)).write_bytes(step.step_bytes(robot))
    return copy


def _findings(kit_dir: Path) -> dict:
    from simkit.check.kit import Kit

    return {f.check: f for f in check_step(Kit.open(kit_dir))}


@pytest.mark.slow
def test_rosie_kit_has_a_checked_step_assembly(rosie_1000):
    path = layout.step("rosie_1000")
    assert path in rosie_1000.files
    with zipfile.ZipFile(rosie_1000.zip_path) as archive:
        assert archive.read(f"rosie_1000_description/{path}") == rosie_1000.files[path]
    found = _findings(rosie_1000.kit_dir)
    assert set(found) == {
        "step.schema",
        "step.products",
        "step.brepcheck",
        "step.volume",
        "step.bounds",
    }
    assert all(f.ok for f in found.values()), [f.line() for f in found.values()]
    doc = json.loads((rosie_1000.kit_dir / "robot.json").read_text())
    assert doc["geometry"]["step"]["file"] == path
    assert doc["geometry"]["step"]["origin"] == "base_link"
    assert path in (rosie_1000.kit_dir / "README.md").read_text()


@pytest.mark.slow
def test_step_check_fails_on_a_link_moved_5_mm(rosie_1000, tmp_path):
    robot = model_from_spec("rosie_1000")
    link = robot.link("link_6")
    moved = tuple(
        dataclasses.replace(s, xyz=(s.xyz[0] + 0.005, s.xyz[1], s.xyz[2])) for s in link.shapes
    )
    links = tuple(dataclasses.replace(x, shapes=moved) if x is link else x for x in robot.links)
    kit = _tampered(rosie_1000.kit_dir, tmp_path, dataclasses.replace(robot, links=links))
    found = _findings(kit)
    assert not found["step.bounds"].ok and "link_6" in found["step.bounds"].detail
    assert found["step.products"].ok
    report = diff_kits(rosie_1000.kit_dir, kit)
    moved_links = {c.name for c in report.changes if c.kind == "step" and c.field == "bbox"}
    assert moved_links == {"link_6"}
    change = next(c for c in report.changes if c.kind == "step" and c.field == "bbox")
    assert np.allclose(np.subtract(change.new, change.old), [5, 0, 0, 5, 0, 0], atol=1e-3)


@pytest.mark.slow
def test_step_check_fails_on_a_removed_solid(rosie_1000, tmp_path):
    robot = model_from_spec("rosie_1000")
    links = tuple(
        dataclasses.replace(x, shapes=()) if x.name == "link_3" else x for x in robot.links
    )
    kit = _tampered(rosie_1000.kit_dir, tmp_path, dataclasses.replace(robot, links=links))
    found = _findings(kit)
    assert not found["step.products"].ok
    assert any(not f.ok for f in run_checks(kit))


@pytest.mark.slow
def test_no_step_build_leaves_the_file_out_and_still_passes(tmp_path):
    result = build(PLANAR, tmp_path, step=False)
    assert not any(p.startswith("step/") for p in result.files)
    doc = json.loads((result.kit_dir / "robot.json").read_text())
    assert doc["geometry"]["step"] is None
    assert all(f.ok for f in result.findings)
    assert "step.file" in {f.check for f in result.findings}


def test_near_duplicate_vertices_are_welded_into_a_valid_solid():
    """A CAD mesh whose corner appears twice, 1e-13 m apart (shorter than Open CASCADE's edge
    tolerance): welded, it is a valid solid with the mesh's volume."""
    from OCP.BRepCheck import BRepCheck_Analyzer

    from simkit.model.robot import Mesh

    box = to_mesh(mf.Manifold.cube((0.1, 0.1, 0.1), center=True))
    vertices = np.vstack([box.vertices, box.vertices[:1] + 1e-13])
    faces = np.array(box.faces)
    first = np.nonzero((faces == 0).any(axis=1))[0][0]
    faces[first][faces[first] == 0] = len(vertices) - 1  # one triangle uses the twin
    solid = brep.faceted_solid(Mesh.of(vertices, faces))
    assert BRepCheck_Analyzer(solid).IsValid()
    assert step_reader.volume(solid) == pytest.approx(1e6, rel=1e-9)  # mm^3


def test_sphere_mesh_holds_within_the_step_checks_one_percent():
    from simkit.derive.solids import primitive_solid

    sphere = _shape("sphere", radius=0.05)
    mesh = to_mesh(primitive_solid(sphere))
    exact = step_reader.volume(brep.primitive_shape(sphere))
    tri = mesh.vertices[mesh.faces]
    meshed = np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6 * 1e9
    assert 0 < 1 - meshed / exact < 0.005


def test_a_cavity_is_an_inner_shell_of_its_solid():
    """A hollow block: the cavity's inward-facing piece becomes the solid's inner shell, not a
    solid of negative volume (which a STEP reader drops)."""
    from OCP.BRepCheck import BRepCheck_Analyzer

    block = mf.Manifold.cube((0.1, 0.1, 0.1), center=True)
    hollow = to_mesh(block - mf.Manifold.cube((0.04, 0.04, 0.04), center=True))
    solids = step_reader.solids_of(brep.link_shape(_link([_shape("mesh", file="x.stl")], hollow)))
    assert len(solids) == 1
    assert BRepCheck_Analyzer(solids[0]).IsValid()
    assert step_reader.volume(solids[0]) == pytest.approx(100**3 - 40**3, rel=1e-9)
