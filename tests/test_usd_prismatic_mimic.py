"""Issue 33: a prismatic mimic follower in the USD (a parallel gripper's second finger). PhysX
does not enforce a mimic on a linear DOF, so the follower carries its leader's servo as its
drive (stiffness, damping, maxForce, aimed at the mimic's offset) and no PhysxMimicJointAPI; a
revolute follower keeps the coupling. The kit check reads the MJCF's joint equality and the
leader's servo independently, and NVIDIA's SimReady rules (DJ.001, DJ.004, DJ.006, DJ.007)
pass on the Isaac asset."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from simkit.check.kit import Kit
from simkit.check.usd import check_usd
from simkit.importer import import_robot
from simkit.pipeline import build
from urdf_parts import link, write

#: the finger's joint damping (N s/m): a follower with damping only, as URDFs often give it
DAMPING = "0.3"


def finger(name: str, y: float, kind: str = "prismatic", mimic: str = "") -> str:
    """A finger on the palm, 0..0.04 m (or rad) along y, with joint damping only."""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="palm"/><child link="{name}_link"/>'
        f'<origin xyz="0 {y} 0.2"/><axis xyz="0 1 0"/>'
        f'<limit lower="0" upper="0.04" effort="20" velocity="0.2"/>'
        f'<dynamics damping="{DAMPING}"/>{mimic}</joint>'
    )


def gripper(folder: Path, kind: str, offset: str = "0") -> Path:
    mimic = f'<mimic joint="left" multiplier="1" offset="{offset}"/>'
    folder.mkdir(parents=True, exist_ok=True)
    return write(
        folder,
        f"grip_{kind}",
        link("palm"),
        link("left_link", "0.1"),
        link("right_link", "0.1"),
        finger("left", 0.03, kind),
        finger("right", -0.03, kind, mimic),
    )


@pytest.fixture(scope="module")
def prismatic_kit(tmp_path_factory):
    root = tmp_path_factory.mktemp("grip")
    spec = import_robot(gripper(root / "src", "prismatic", "0.001"), root / "spec").spec_path
    return build(str(spec), root / "kit")


def _joint(kit: Path, name: str):
    from pxr import Usd

    stage = Usd.Stage.Open(str(next((kit / "usd").glob("*.usda"))))
    return stage, stage.GetPrimAtPath(f"{stage.GetDefaultPrim().GetPath()}/joints/{name}")


def test_prismatic_follower_carries_its_leaders_servo(prismatic_kit):
    from pxr import UsdPhysics

    stage, right = _joint(prismatic_kit.kit_dir, "right")
    left = stage.GetPrimAtPath(right.GetPath().GetParentPath().AppendChild("left"))
    assert not any(str(s).startswith("PhysxMimicJointAPI") for s in right.GetAppliedSchemas())
    lead, follow = (UsdPhysics.DriveAPI.Get(p, "linear") for p in (left, right))
    for attr in ("Stiffness", "Damping", "MaxForce"):
        value = getattr(follow, f"Get{attr}Attr")().Get()
        assert value == getattr(lead, f"Get{attr}Attr")().Get() and 0 < value < float("inf")
    assert follow.GetTargetPositionAttr().Get() == pytest.approx(0.001)  # the mimic's offset
    assert (
        right.HasAPI(UsdPhysics.DriveAPI, "linear")
        and right.GetAttribute("state:linear:physics:position").IsValid()
    )
    found = {f.check: f for f in prismatic_kit.findings}
    assert found["usd.drive.stiffness"].ok and found["usd.drive.targetPosition"].ok
    assert found["usd.limits_drives"].ok


def test_a_follower_drive_off_its_leaders_servo_fails(prismatic_kit, tmp_path):
    kit = tmp_path / "kit"
    shutil.copytree(prismatic_kit.kit_dir, kit)
    physics = next((kit / "usd").glob("*/payloads/physics.usda"))
    text = physics.read_text(encoding="utf-8")
    head, tail = text.split('def PhysicsPrismaticJoint "right"')
    old = "float drive:linear:physics:stiffness = "
    assert old in tail
    physics.write_text(head + 'def PhysicsPrismaticJoint "right"' + tail.replace(old, old + "1"))
    assert "usd.drive.stiffness" in {f.check for f in check_usd(Kit.open(kit)) if not f.ok}


def test_revolute_follower_keeps_the_mimic_coupling_and_no_drive(tmp_path):
    """PhysX enforces an angular mimic; the rules want the coupling to own the DOF, so the
    follower's joint damping gives it no drive (DJ.004, DJ.006)."""
    from simkit.emit.usd.physics import physics_text
    from simkit.pipeline import model_from_spec

    spec = import_robot(gripper(tmp_path / "src", "revolute"), tmp_path / "spec").spec_path
    text = physics_text(model_from_spec(str(spec)))
    right = text.split('def PhysicsRevoluteJoint "right"')[1].split("}")[0]
    assert "PhysxMimicJointAPI:rotY" in right and "PhysicsDriveAPI" not in right
    left = text.split('def PhysicsRevoluteJoint "left"')[1].split("}")[0]
    assert "PhysicsDriveAPI:angular" in left
    usd = [f for f in build(str(spec), tmp_path / "kit").findings if f.check.startswith("usd.")]
    assert [f.line() for f in usd if not f.ok] == [] and len(usd) > 40


def test_prismatic_follower_passes_simready_driven_joints(prismatic_kit):
    from test_usd_simready import _lines, _validators

    _validators()
    entry = next((prismatic_kit.kit_dir / "usd").glob("*.usda"))
    assert _lines(entry.parent / entry.stem / entry.name) == ([], [])
