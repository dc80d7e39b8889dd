"""A joint's effort limit survives the kit's USD (issue 39): the kit writes the spec's
`effort_peak` (the URDF `<limit effort>`) as the joint's `simkit:effortLimit`, apart from the
drive's `maxForce` (the servo's force, which simulators apply, unchanged), and the USD import
reads the joint's effort from `simkit:effortLimit` where the joint carries it (and the drive's
`maxForce` as the spec's `drive_peak_torque_at_joint`, the servo's force), else from
`maxForce` (a converter's USD)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from simkit.emit.usd.physics import EFFORT_LIMIT
from simkit.importer import import_robot
from simkit.importer.formats.usd.limits import EFFORT_LIMIT as READ_EFFORT_LIMIT
from usd_stages import BASE_AND_ARM, stage_text

pytest.importorskip("pxr")

#: a one-joint arm: `base` bolted to the world, `arm` on a revolute joint about Z whose drive
#: has maxForce 56.4 N m; EFFORT is replaced by the joint's effort attribute line (or nothing)
HINGE = """    def PhysicsRevoluteJoint "hinge" (prepend apiSchemas = ["PhysicsDriveAPI:angular"])
    {{
        rel physics:body0 = </bot/base>
        rel physics:body1 = </bot/arm>
        point3f physics:localPos0 = (0, 0, 0.5)
        uniform token physics:axis = "Z"
        float physics:lowerLimit = -90
        float physics:upperLimit = 90
        float drive:angular:physics:maxForce = 56.4
        {effort}
    }}
"""


def _hinge(tmp_path: Path, effort_line: str, meters: float = 1.0) -> dict:
    """The imported spec's hinge joint."""
    usda = tmp_path / "bot.usda"
    usda.write_text(stage_text(BASE_AND_ARM + HINGE.format(effort=effort_line), meters))
    done = import_robot(usda, tmp_path / "out")
    joints = {j["name"]: j for j in yaml.safe_load(done.spec_path.read_text())["joints"]}
    return joints["hinge"]


def test_reader_and_writer_agree_on_the_name() -> None:
    assert EFFORT_LIMIT == READ_EFFORT_LIMIT == "simkit:effortLimit"


def test_effort_limit_is_the_effort_and_max_force_the_servo(tmp_path) -> None:
    hinge = _hinge(tmp_path, "custom float simkit:effortLimit = 100")
    assert hinge["effort_peak"] == 100
    assert hinge["drive_peak_torque_at_joint"] == pytest.approx(56.4)


def test_without_it_max_force_is_the_effort(tmp_path) -> None:
    hinge = _hinge(tmp_path, "")
    assert hinge["effort_peak"] == pytest.approx(56.4)
    assert "drive_peak_torque_at_joint" not in hinge


def test_effort_limit_in_stage_units(tmp_path) -> None:
    """Like maxForce, in kilograms times stage units squared: 1e4 kg cm^2/s^2 is 1 N m (so
    the 56.4 maxForce is 0.00564 N m here)."""
    hinge = _hinge(tmp_path, "custom float simkit:effortLimit = 1e6", 0.01)
    assert hinge["effort_peak"] == pytest.approx(100)
    assert hinge["drive_peak_torque_at_joint"] == pytest.approx(0.00564)


@pytest.mark.slow
def test_seed_kit_usd_carries_the_effort_limit(kit_factory, tmp_path) -> None:
    """ecn_2r (effort_peak 100 N m, a servo of 56.4 N m): the kit's physics layer keeps the
    servo as maxForce and the limit as simkit:effortLimit; its USD imports back with the
    spec's effort."""
    from pxr import Usd

    kit = kit_factory("ecn_2r").kit_dir
    spec = yaml.safe_load((Path(__file__).parents[1] / "robots" / "ecn_2r.yaml").read_text())
    want = {j["name"]: j["effort_peak"] for j in spec["joints"] if "effort_peak" in j}
    stage = Usd.Stage.Open(str(kit / "usd" / "ecn_2r" / "payloads" / "physics.usda"))
    for name, effort in want.items():
        prim = stage.GetPrimAtPath(f"/ecn_2r/joints/{name}")
        assert prim.GetAttribute(EFFORT_LIMIT).Get() == effort
        assert prim.GetAttribute("drive:angular:physics:maxForce").Get() == pytest.approx(56.4)
    done = import_robot(kit / "usd" / "ecn_2r.usda", tmp_path / "spec")
    joints = [j for j in yaml.safe_load(done.spec_path.read_text())["joints"] if j["name"] in want]
    assert {j["name"]: j.get("effort_peak") for j in joints} == want
    assert [j.get("drive_peak_torque_at_joint") for j in joints] == [56.4] * len(want)
