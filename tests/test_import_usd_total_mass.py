"""A USD whose PhysicsScene keeps MuJoCo's `settotalmass` (MjcPhysics
`mjc:compiler:setTotalMass`, as mujoco-usd-converter writes it) imports with its masses and
inertias scaled to that total, as MuJoCo compiles it; not where the stage holds other
rigid bodies, whose masses the total includes."""

from __future__ import annotations

import pytest
import yaml
from tests.usd_stages import arm

from simkit.importer import import_robot

pytest.importorskip("pxr")


def _total_mass_arm(tmp_path, total: float, loose: bool = False):
    """The test arm (base 2 kg, upper 1 kg, slider 0.5 kg; diagonal inertia 0.01, 0.02,
    0.03 kg m^2 each) with a PhysicsScene setting the total mass; with `loose`, a rigid body
    on the stage that no joint joins to the robot."""
    from pxr import Sdf, Usd, UsdGeom, UsdPhysics

    path = arm(tmp_path / "arm.usda")
    stage = Usd.Stage.Open(str(path))
    scene = UsdPhysics.Scene.Define(stage, "/PhysicsScene")
    attr = scene.GetPrim().CreateAttribute("mjc:compiler:setTotalMass", Sdf.ValueTypeNames.Double)
    attr.Set(total)
    if loose:
        ball = UsdGeom.Xform.Define(stage, "/ball")
        UsdPhysics.RigidBodyAPI.Apply(ball.GetPrim())
    stage.GetRootLayer().Save()
    done = import_robot(path, tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    return {link["name"]: link for link in spec["links"]}, spec


def test_scaled_to_total(tmp_path) -> None:
    """Total 7 kg over 3.5 kg of bodies: every mass and inertia doubled, and listed."""
    links, spec = _total_mass_arm(tmp_path, 7.0)
    assert links["base"]["mass"] == pytest.approx(4.0)
    assert links["upper"]["mass"] == pytest.approx(2.0)
    assert links["slider"]["mass"] == pytest.approx(1.0)
    inertia = links["upper"]["inertia"]
    assert [inertia[k] for k in ("ixx", "iyy", "izz")] == pytest.approx([0.02, 0.04, 0.06])
    listed = {item["what"] for item in spec["source_differences"]}
    assert {"links.upper.mass", "links.upper.inertia"} <= listed


def test_not_scaled_with_other_bodies(tmp_path) -> None:
    """A loose rigid body on the stage: the factor is unknown, the masses stay authored."""
    links, spec = _total_mass_arm(tmp_path, 7.0, loose=True)
    assert links["base"]["mass"] == pytest.approx(2.0)
    assert any("not applied" in str(item) for item in spec["source_differences"])
