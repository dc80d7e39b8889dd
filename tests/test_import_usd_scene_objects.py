"""A USD scene that holds the robot and an object on its own joints to the world (a
manipulation task's pen): the object's body and joints are left out and each listed in
`source_differences`, so the build's source check, which reads the whole stage, accepts
them as the import's listed differences."""

from __future__ import annotations

import pytest
import yaml
from tests.usd_stages import arm

from simkit.importer import import_robot

pytest.importorskip("pxr")


def test_scene_object_listed(tmp_path) -> None:
    """`ball` on a prismatic joint `ball_slide` from the world: not imported, both listed."""
    from pxr import Usd, UsdGeom, UsdPhysics

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    ball = UsdGeom.Xform.Define(stage, "/ball")
    UsdPhysics.RigidBodyAPI.Apply(ball.GetPrim())
    slide = UsdPhysics.PrismaticJoint.Define(stage, "/ball/ball_slide")
    slide.CreateBody1Rel().SetTargets([ball.GetPath()])
    slide.CreateAxisAttr("X")
    stage.GetRootLayer().Save()
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    assert "ball" not in {link["name"] for link in spec["links"]}
    listed = {item["what"] for item in spec["source_differences"]}
    assert {"links.ball", "joints.ball_slide"} <= listed
    assert "joints.shoulder" not in listed


def test_names_as_in_the_whole_stage(tmp_path) -> None:
    """The object's joint `/a_ball/shoulder` comes first in path order: it is `shoulder`,
    the robot's is `shoulder_1`, as usd-core's parser names them for the source check."""
    from pxr import Usd, UsdGeom, UsdPhysics

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    ball = UsdGeom.Xform.Define(stage, "/a_ball")
    UsdPhysics.RigidBodyAPI.Apply(ball.GetPrim())
    twist = UsdPhysics.RevoluteJoint.Define(stage, "/a_ball/shoulder")
    twist.CreateBody1Rel().SetTargets([ball.GetPath()])
    stage.GetRootLayer().Save()
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    joints = {joint["name"]: joint for joint in spec["joints"]}
    assert joints["shoulder_1"]["parent"] == "base" and "shoulder" not in joints
    assert "joints.shoulder" in {item["what"] for item in spec["source_differences"]}


def test_welded_target_listed(tmp_path) -> None:
    """A MuJoCo mocap body as mujoco-usd-converter writes it: `target`, bolted to the world
    (`target_bolt`) and welded to `upper` by a joint excluded from the articulation: the
    tree does not reach it; both it and its bolt are listed, not imported."""
    from pxr import Usd, UsdGeom, UsdPhysics

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    target = UsdGeom.Xform.Define(stage, "/target")
    UsdPhysics.RigidBodyAPI.Apply(target.GetPrim())
    bolt = UsdPhysics.FixedJoint.Define(stage, "/target/target_bolt")
    bolt.CreateBody1Rel().SetTargets([target.GetPath()])
    weld = UsdPhysics.FixedJoint.Define(stage, "/target/weld")
    weld.CreateBody0Rel().SetTargets([target.GetPath()])
    weld.CreateBody1Rel().SetTargets(["/arm0/upper"])
    weld.CreateExcludeFromArticulationAttr(True)
    stage.GetRootLayer().Save()
    spec = yaml.safe_load(import_robot(path, tmp_path / "out").spec_path.read_text())
    assert "target" not in {link["name"] for link in spec["links"]}
    listed = {item["what"] for item in spec["source_differences"]}
    assert {"links.target", "joints.target_bolt"} <= listed
