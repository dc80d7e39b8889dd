"""A floating USD robot that cannot stand on the kit's servos (a tall body on one thin leg)
is built, not refused: the import marks it as needing active balance, as for an MJCF."""

from __future__ import annotations

import pytest
import yaml

from simkit.importer import import_robot

pytest.importorskip("pxr")


def _stilt(path):
    """`torso` (5 kg box, its CoM 0.3 m to the side) on a revolute joint atop `leg` (a 1 m
    capsule), no joint to the world: a floating robot that tips over its rounded point."""
    from pxr import Gf, Usd, UsdGeom, UsdPhysics

    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)  # unset, a stage is in centimetres
    top = UsdGeom.Xform.Define(stage, "/stilt")
    stage.SetDefaultPrim(top.GetPrim())
    UsdPhysics.ArticulationRootAPI.Apply(top.GetPrim())
    for name, z, mass in (("leg", 0.5, 0.5), ("torso", 1.1, 5.0)):
        body = UsdGeom.Xform.Define(stage, f"/stilt/{name}")
        body.AddTranslateOp().Set(Gf.Vec3d(0, 0, z))
        UsdPhysics.RigidBodyAPI.Apply(body.GetPrim())
        api = UsdPhysics.MassAPI.Apply(body.GetPrim())
        api.CreateMassAttr(mass)
        api.CreateCenterOfMassAttr(Gf.Vec3f(0, 0.3 if name == "torso" else 0, 0))
        api.CreateDiagonalInertiaAttr(Gf.Vec3f(0.02, 0.02, 0.02))
        if name == "leg":
            shape = UsdGeom.Capsule.Define(stage, f"/stilt/{name}/shape")
            shape.CreateRadiusAttr(0.02)
            shape.CreateHeightAttr(0.96)
        else:
            shape = UsdGeom.Cube.Define(stage, f"/stilt/{name}/shape")
            shape.CreateSizeAttr(0.2)
        UsdPhysics.CollisionAPI.Apply(shape.GetPrim())
    hinge = UsdPhysics.RevoluteJoint.Define(stage, "/stilt/hip")
    hinge.CreateBody0Rel().SetTargets(["/stilt/leg"])
    hinge.CreateBody1Rel().SetTargets(["/stilt/torso"])
    hinge.CreateLocalPos0Attr(Gf.Vec3f(0, 0, 0.5))
    hinge.CreateLocalPos1Attr(Gf.Vec3f(0, 0, -0.1))
    hinge.CreateAxisAttr("X")
    hinge.CreateLowerLimitAttr(-30.0)
    hinge.CreateUpperLimitAttr(30.0)
    stage.GetRootLayer().Save()
    return path


def test_falling_base_marked(tmp_path) -> None:
    done = import_robot(_stilt(tmp_path / "stilt.usda"), tmp_path / "out", floating=True)
    spec = yaml.safe_load(done.spec_path.read_text())
    assert "its base sinks" in spec.get("needs_active_balance", "")
    assert any("needs active balance" in line for line in done.lines)
