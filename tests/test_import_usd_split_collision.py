"""A USD body whose collision is one source split into many convex meshes (the URDF
converter writes a `<collision>` OBJ of many objects as sibling Mesh prims under one Xform):
the meshes count as one given source, each kept as its own convex piece, not as many
sources that push the link past the cap on given collision meshes to CoACD (`auto`)."""

from __future__ import annotations

import pytest
import yaml
from tests.usd_stages import arm

from simkit.importer import import_robot
from simkit.importer.translate.links import MAX_GIVEN, MAX_GIVEN_PIECES

pytest.importorskip("pxr")

PIECES = MAX_GIVEN + 2  # more meshes than the cap on given sources
CORNERS = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
QUADS = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]


def _mesh(stage, path: str, x: float, dent: bool):
    """A 2 cm cube mesh at `x` (m) along the body's X; `dent`: one corner pushed in past the
    cube's centre, so the mesh is concave."""
    from pxr import Gf, UsdGeom, UsdPhysics

    points = [Gf.Vec3f(x + 0.02 * a, 0.02 * b, 0.02 * c) for a, b, c in CORNERS]
    if dent:
        points[7] = Gf.Vec3f(x + 0.005, 0.005, 0.005)
    mesh = UsdGeom.Mesh.Define(stage, path)
    mesh.CreatePointsAttr(points)
    mesh.CreateFaceVertexCountsAttr([4] * len(QUADS))
    mesh.CreateFaceVertexIndicesAttr([i for quad in QUADS for i in quad])
    UsdPhysics.CollisionAPI.Apply(mesh.GetPrim())


def _collision(tmp_path, grouped: bool = True, dent: bool = False, pieces: int = PIECES) -> dict:
    """The spec of `upper` in the test arm, given `pieces` collision cube meshes: below one
    Xform (`grouped`) or right below the body; `dent`: the first one concave."""
    from pxr import Usd, UsdGeom

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    parent = "/arm0/upper/split_hull" if grouped else "/arm0/upper"
    UsdGeom.Xform.Define(stage, parent)
    for k in range(pieces):
        _mesh(stage, f"{parent}/convex_{k}", 0.1 + 0.03 * k, dent and k == 0)
    stage.GetRootLayer().Save()
    done = import_robot(path, tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    return next(link for link in spec["links"] if link["name"] == "upper")


def test_grouped_convex_meshes_are_one_given_source(tmp_path) -> None:
    upper = _collision(tmp_path)
    assert upper["collision"] == "given"
    meshes = [s for s in upper["collision_shapes"] if s["shape"] == "mesh"]
    assert len(meshes) == PIECES
    assert len({s["file"] for s in meshes}) == PIECES  # each piece its own convex mesh


def test_meshes_right_below_the_body_are_sources_each(tmp_path) -> None:
    """No grouping prim: each mesh is a `<collision>` of its own, so the cap holds."""
    assert _collision(tmp_path, grouped=False)["collision"] == "auto"


def test_a_concave_mesh_leaves_the_group_sources_each(tmp_path) -> None:
    """A group with a concave mesh is no convex decomposition: each mesh counts."""
    assert _collision(tmp_path, dent=True)["collision"] == "auto"


def test_too_many_pieces_go_to_coacd(tmp_path) -> None:
    """More pieces than the kit merges cheaply (quadratic in them): the CoACD path."""
    assert _collision(tmp_path, pieces=MAX_GIVEN_PIECES + 1)["collision"] == "auto"
