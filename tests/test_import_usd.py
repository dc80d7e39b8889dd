"""USD import (issue 39): a UsdPhysics articulation read from the composed stage."""

from __future__ import annotations

import math

import pytest
import yaml
from tests.usd_stages import arm

from simkit.errors import SpecError
from simkit.importer import import_robot
from simkit.importer.read.options import ReadOptions

pytest.importorskip("pxr")


def _spec(tmp_path, **kwargs) -> dict:
    variant = kwargs.pop("pick", None)
    path = arm(tmp_path / "arm.usda", **kwargs)
    done = import_robot(path, tmp_path / "out", reading=ReadOptions(variant=variant))
    return yaml.safe_load(done.spec_path.read_text())


def _by_name(items: list[dict]) -> dict[str, dict]:
    return {item["name"]: item for item in items}


def test_two_link_arm(tmp_path) -> None:
    """MassAPI masses, a revolute with limits in degrees, a prismatic, a fixed base."""
    spec = _spec(tmp_path)
    links, joints = _by_name(spec["links"]), _by_name(spec["joints"])
    assert links["base"]["mass"] == 2.0 and links["upper"]["mass"] == 1.0
    assert links["upper"]["com"] == pytest.approx([0, 0, 0.1])
    assert joints["shoulder"]["type"] == "revolute"
    assert joints["shoulder"]["lower"] == pytest.approx(math.radians(-90))
    assert joints["shoulder"]["upper"] == pytest.approx(math.radians(45))
    assert joints["shoulder"]["xyz"] == pytest.approx([0, 0, 0.5])
    assert joints["slide"]["type"] == "prismatic" and joints["slide"]["upper"] == pytest.approx(0.2)
    assert joints["world_joint"]["parent"] == "world" and spec["root"] == "world"
    assert spec["source"]["format"] == "usd"


def test_centimetres(tmp_path) -> None:
    """metersPerUnit 0.01: lengths (joint origins, limits, CoM) scaled to metres."""
    spec = _spec(tmp_path, meters=0.01)
    joints, links = _by_name(spec["joints"]), _by_name(spec["links"])
    assert joints["shoulder"]["xyz"] == pytest.approx([0, 0, 0.5])
    assert joints["slide"]["upper"] == pytest.approx(0.2)
    assert links["upper"]["com"] == pytest.approx([0, 0, 0.1])
    assert links["upper"]["inertia"]["izz"] == pytest.approx(0.03, rel=1e-6)


def test_y_up(tmp_path) -> None:
    """A Y-up stage is turned Z up where the robot meets the world (the base joint)."""
    spec = _spec(tmp_path, y_up=True)
    base = _by_name(spec["joints"])["world_joint"]
    assert base.get("rpy", [0, 0, 0]) == pytest.approx([math.pi / 2, 0, 0])


def test_variant(tmp_path) -> None:
    """The default Physics variant, and the one --variant names; an unknown one refused."""
    assert _by_name(_spec(tmp_path / "a", variant=True)["links"])["upper"]["mass"] == 1.0
    heavy = _spec(tmp_path / "b", variant=True, pick="heavy")
    assert _by_name(heavy["links"])["upper"]["mass"] == 3.0
    assert heavy["source"]["args"] == {"variant": "heavy"}
    with pytest.raises(SpecError, match="no Physics variant 'nope'"):
        _spec(tmp_path / "c", variant=True, pick="nope")


def test_no_articulation(tmp_path) -> None:
    from pxr import Usd, UsdGeom

    path = tmp_path / "empty.usda"
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.Xform.Define(stage, "/thing")
    stage.GetRootLayer().Save()
    with pytest.raises(SpecError, match="no articulation") as caught:
        import_robot(path, tmp_path / "out")
    assert "\n" not in str(caught.value)
    assert not (tmp_path / "out").exists()


def test_two_robots(tmp_path) -> None:
    path = arm(tmp_path / "two.usda", robots=2)
    with pytest.raises(SpecError, match="several robots") as caught:
        import_robot(path, tmp_path / "out")
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("excluded", [True, False])
def test_closed_loop_dropped(tmp_path, excluded: bool) -> None:
    """A loop-closing joint (excludeFromArticulation, or a body's second parent joint) is
    left out of the kit's tree, one report line, listed in source_differences."""
    path = arm(tmp_path / "arm.usda", loop=excluded)
    done = import_robot(path, tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert "zloop" not in _by_name(spec["joints"])
    assert "joints.zloop" in {d["what"] for d in spec["source_differences"]}
    assert any("zloop" in line and "closed loop" in line for line in done.lines)


def test_two_joints_one_pair(tmp_path) -> None:
    """Two joints between one pair of bodies (a body with two degrees of freedom): a chain
    through an added massless link, in the stage's order, listed as added."""
    path = arm(tmp_path / "arm.usda", chain=True)
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    joints = _by_name(spec["joints"])
    assert (joints["shoulder"]["parent"], joints["shoulder"]["child"]) == ("base", "shoulder_link")
    assert (joints["a_twist"]["parent"], joints["a_twist"]["child"]) == ("shoulder_link", "upper")
    assert joints["a_twist"]["axis"] == [1.0, 0.0, 0.0]
    assert "links.shoulder_link" in {d["what"] for d in spec["source_differences"]}


def test_display_names(tmp_path) -> None:
    """A prim's displayName (the source's own name, kept there by converters when it is no
    USD identifier) names its link or joint."""
    from pxr import Usd

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    stage.GetPrimAtPath("/arm0/shoulder").SetDisplayName("hip_pitch")
    stage.GetPrimAtPath("/arm0/upper").SetDisplayName("thigh")
    stage.GetRootLayer().Save()
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    joints = _by_name(spec["joints"])
    assert joints["hip_pitch"]["child"] == "thigh" and "thigh" in _by_name(spec["links"])


def test_flat_mesh_left_out(tmp_path) -> None:
    """A visual mesh that encloses no volume (a sheet) is left out and listed, not a build
    failure."""
    from pxr import Gf, Usd, UsdGeom

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    sheet = UsdGeom.Mesh.Define(stage, "/arm0/upper/sheet")
    sheet.CreatePointsAttr(
        [Gf.Vec3f(0, 0, 0), Gf.Vec3f(1, 0, 0), Gf.Vec3f(1, 1, 0), Gf.Vec3f(0, 1, 0)]
    )
    sheet.CreateFaceVertexCountsAttr([4])
    sheet.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    stage.GetRootLayer().Save()
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    assert "links.upper.visual.sheet" in {d["what"] for d in spec["source_differences"]}


def test_loose_body_noted(tmp_path) -> None:
    """A rigid body joined to nothing (a scene's object) is not imported: one line says so."""
    from pxr import Usd, UsdGeom, UsdPhysics

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    ball = UsdGeom.Xform.Define(stage, "/ball")
    UsdPhysics.RigidBodyAPI.Apply(ball.GetPrim())
    stage.GetRootLayer().Save()
    done = import_robot(path, tmp_path / "out")
    assert any("1 rigid bodies not joined to the robot (first /ball)" in x for x in done.lines)
    assert "ball" not in _by_name(yaml.safe_load(done.spec_path.read_text())["links"])


def test_world_joints_chain(tmp_path) -> None:
    """Several joints holding the root body to the world (a base on slides and a hinge, as
    MJCF writes a mobile base) are a chain from the world link, in the stage's order."""
    path = arm(tmp_path / "arm.usda", rail=True)
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    joints = _by_name(spec["joints"])
    assert (joints["rail"]["parent"], joints["rail"]["child"]) == ("world", "rail_link")
    assert (joints["yaw"]["parent"], joints["yaw"]["child"]) == ("rail_link", "base")
    assert joints["rail"]["type"] == "prismatic" and joints["yaw"]["type"] == "continuous"


def test_two_articulations_of_one_robot(tmp_path) -> None:
    """Several articulation roots each bolted to the world by a fixed joint from the robot's
    own prim (urdf-usd-converter's form of a massless root link with several fixed children)
    are one fixed-base robot; bolted by joints from nowhere they are two robots (above)."""
    path = arm(tmp_path / "arm.usda", two_roots=True)
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    joints = _by_name(spec["joints"])
    assert (joints["post_joint"]["parent"], joints["post_joint"]["child"]) == ("world", "post")
    assert joints["post_joint"]["xyz"] == pytest.approx([0.3, 0, 0])
    assert _by_name(spec["links"])["post"]["mass"] == 0.7


def test_zero_inertia_without_com(tmp_path) -> None:
    """A MassAPI with a mass and moments written as zero but no centerOfMass (a URDF link
    whose inertial has no origin, as urdf-usd-converter writes it) has its CoM at the body
    origin, not at its collider's centre."""
    from pxr import Gf, Usd, UsdGeom, UsdPhysics

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    api = UsdPhysics.MassAPI(stage.GetPrimAtPath("/arm0/slider"))
    api.GetCenterOfMassAttr().Clear()
    api.GetDiagonalInertiaAttr().Set(Gf.Vec3f(0, 0, 0))
    UsdGeom.Xformable(stage.GetPrimAtPath("/arm0/slider/box")).AddTranslateOp().Set(
        Gf.Vec3d(0.2, 0, 0)
    )
    stage.GetRootLayer().Save()
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    assert _by_name(spec["links"])["slider"]["com"] == pytest.approx([0, 0, 0])
