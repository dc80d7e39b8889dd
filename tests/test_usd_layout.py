"""Issue 33: the USD asset's files, layers and variants as Isaac Sim's robot asset structure
lays them out, and the robot type rule (fast: emitter output only, no kit build)."""

from __future__ import annotations

from pathlib import Path

import pytest

from simkit.emit import usd
from simkit.emit.usd.robot_schema import robot_type
from simkit.pipeline import model_from_spec

SPECS = Path(__file__).resolve().parent / "specs"
PAYLOADS = ("base.usda", "geometries.usd", "instances.usda", "materials.usda")


@pytest.mark.parametrize(
    ("target", "kind"),
    [
        ("rosie_1000", "Manipulator"),  # fixed to the world
        ("ecn_2r", "Manipulator"),
        ("asimov", "Humanoid"),  # floating pelvis, two legs
        (str(SPECS / "usd_mix.yaml"), "Wheeled"),  # floating, a continuous joint, no limb
    ],
)
def test_robot_type_follows_the_rule(target, kind):
    assert robot_type(model_from_spec(target)) == kind


def test_files_and_layers(tmp_path):
    from pxr import Sdf, Usd, UsdGeom

    robot = model_from_spec("ecn_2r")
    files = usd.emit(robot)
    layers = (*PAYLOADS, "physics.usda", "physx.usda", "mujoco.usda")
    names = {f"usd/ecn_2r/payloads/{n}" for n in layers}
    assert set(files) == {
        "usd/ecn_2r.usda",
        "usd/.thumbs/256x256/ecn_2r.usda.png",
        "usd/ecn_2r/ecn_2r.usda",  # the Isaac asset: its folder is named as the file (RC.003)
        "usd/ecn_2r/.thumbs/256x256/ecn_2r.usda.png",
        *names,
    }
    for rel, data in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_bytes(data)
        if rel.endswith((".usd", ".usda")):
            assert data.startswith(b"#usda 1.0"), rel  # text, so that reviews see changes
            layer = Sdf.Layer.FindOrOpen(str(tmp_path / rel))
            assert layer.defaultPrim, rel
    for rel, base in (
        ("usd/ecn_2r/ecn_2r.usda", "./payloads/base.usda"),
        ("usd/ecn_2r.usda", "./ecn_2r/payloads/base.usda"),
    ):  # two interface layers over one set of payloads
        stage = Usd.Stage.Open(str(tmp_path / rel))
        top = stage.GetDefaultPrim()
        spec = stage.GetRootLayer().GetPrimAtPath(top.GetPath())
        assert [str(r.assetPath) for r in spec.referenceList.prependedItems] == [base]
    assert files["usd/ecn_2r.usda"] == files["usd/ecn_2r/ecn_2r.usda"].replace(
        b"@./payloads/", b"@./ecn_2r/payloads/"
    )
    variants = top.GetVariantSet("Physics")
    assert variants.GetVariantNames() == ["mujoco", "none", "physics", "physx"]
    assert variants.GetVariantSelection() == "physx"
    assert UsdGeom.GetStageUpAxis(stage) == "Z" and Usd.ModelAPI(top).GetKind() == "component"
    meta = stage.GetRootLayer().customLayerData["SimReady_Metadata"]
    assert meta["asset_type"] == "robot" and meta["rigid_body_count"] == 3
    assert meta["mass"] == pytest.approx(robot.total_mass, rel=1e-9)


def test_binary_format_writes_the_entry_and_the_geometry_as_crates():
    files = usd.emit_binary(model_from_spec("ecn_2r"))
    assert files["usd/ecn_2r.usdc"].startswith(b"PXR-USDC")
    assert files["usd/ecn_2r/ecn_2r.usdc"].startswith(b"PXR-USDC")
    assert files["usd/ecn_2r/payloads/geometries.usd"].startswith(b"PXR-USDC")
    assert files["usd/ecn_2r/payloads/physics.usda"].startswith(b"#usda 1.0")
    assert "usd/.thumbs/256x256/ecn_2r.usdc.png" in files
    assert "usd/ecn_2r/.thumbs/256x256/ecn_2r.usdc.png" in files
