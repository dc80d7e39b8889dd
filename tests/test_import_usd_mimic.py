"""A USD mimic joint comes back as the spec's `mimic` (issue 39): Newton's `NewtonMimicAPI`
(urdf-usd-converter's; q = coef0 + coef1 q_leader, coef0 in degrees or stage distance) and
PhysX's `PhysxMimicJointAPI:<inst>` (a simkit kit's and Isaac Sim's; q + gearing q_leader +
offset = 0), neither registered with usd-core (importer/formats/usd/mimic.py). A mimic whose
leader is no joint of the robot gives one report line and an independent joint, as a URDF's
does; a simkit kit's revolute follower comes back through its own USD."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from simkit.importer import import_robot
from usd_stages import body_text, bolted_text, stage_text

pytest.importorskip("pxr")

#: a palm bolted to the world with two fingers on KIND joints about Y (`left` the leader,
#: `right` the follower); SCHEMAS is the follower's apiSchemas, MIMIC its mimic attributes
FINGERS = (
    body_text("palm", 2)
    + body_text("left_link", 0.1, at=(0, 0.3, 0.2), inertia=(0.001,) * 3, box=False)
    + body_text("right_link", 0.1, at=(0, -0.3, 0.2), inertia=(0.001,) * 3, box=False)
    + bolted_text("palm")
)
JOINTS = """    def Physics{kind}Joint "left"
    {{
        rel physics:body0 = </bot/palm>
        rel physics:body1 = </bot/left_link>
        point3f physics:localPos0 = (0, 0.3, 0.2)
        uniform token physics:axis = "Y"
        float physics:lowerLimit = -40
        float physics:upperLimit = 40
    }}
    def Physics{kind}Joint "right" (prepend apiSchemas = [{schemas}])
    {{
        rel physics:body0 = </bot/palm>
        rel physics:body1 = </bot/right_link>
        point3f physics:localPos0 = (0, -0.3, 0.2)
        uniform token physics:axis = "Y"
        float physics:lowerLimit = -90
        float physics:upperLimit = 90
        {mimic}
    }}
"""

NEWTON = """prepend rel newton:mimicJoint = </bot/left>
        float newton:mimicCoef0 = 5.729578
        float newton:mimicCoef1 = -0.5"""
PHYSX = """rel physxMimicJoint:rotY:referenceJoint = </bot/left>
        uniform token physxMimicJoint:rotY:referenceJointAxis = "rotY"
        float physxMimicJoint:rotY:gearing = 0.5
        float physxMimicJoint:rotY:offset = -5.729578"""


def _joints(tmp_path: Path, schemas: str, mimic: str, kind: str = "Revolute", meters=1.0):
    """(the imported spec's joints by name, the import's report lines)."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    usda = tmp_path / "bot.usda"
    text = JOINTS.format(kind=kind, schemas=schemas, mimic=mimic)
    usda.write_text(stage_text(FINGERS + text, meters))
    done = import_robot(usda, tmp_path / "out")
    joints = {j["name"]: j for j in yaml.safe_load(done.spec_path.read_text())["joints"]}
    return joints, done.lines


def test_newton_mimic(tmp_path) -> None:
    """coef1 is the multiplier, coef0 the offset in degrees (0.1 rad here)."""
    joints, _ = _joints(tmp_path, '"NewtonJointAPI", "NewtonMimicAPI"', NEWTON)
    mimic = joints["right"]["mimic"]
    assert mimic["joint"] == "left" and mimic["multiplier"] == -0.5
    assert mimic["offset"] == pytest.approx(0.1, abs=1e-7)
    assert "mimic" not in joints["left"]


def test_newton_fallbacks_and_disabled(tmp_path) -> None:
    """Unauthored coefficients are the schema's fallbacks (coef0 0, coef1 1), as
    urdf-usd-converter leaves them; `newton:mimicEnabled = false` is no mimic."""
    rel = "prepend rel newton:mimicJoint = </bot/left>"
    joints, _ = _joints(tmp_path / "a", '"NewtonMimicAPI"', rel)
    assert joints["right"]["mimic"] == {"joint": "left", "multiplier": 1.0, "offset": 0.0}
    off = f"{rel}\nbool newton:mimicEnabled = false"
    joints, _ = _joints(tmp_path / "b", '"NewtonMimicAPI"', off)
    assert "mimic" not in joints["right"]


def test_physx_mimic_gearing_sign(tmp_path) -> None:
    """q + gearing q_leader + offset = 0: gearing 0.5 is multiplier -0.5, offset -5.73 deg
    is +0.1 rad."""
    joints, _ = _joints(tmp_path, '"PhysxMimicJointAPI:rotY"', PHYSX)
    mimic = joints["right"]["mimic"]
    assert mimic["joint"] == "left" and mimic["multiplier"] == -0.5
    assert mimic["offset"] == pytest.approx(0.1, abs=1e-7)


def test_prismatic_offset_in_stage_units(tmp_path) -> None:
    """A centimetre stage: a prismatic follower's coef0 of 2 is 0.02 m."""
    mimic = NEWTON.replace("5.729578", "2")
    joints, _ = _joints(tmp_path, '"NewtonMimicAPI"', mimic, kind="Prismatic", meters=0.01)
    assert joints["right"]["mimic"]["offset"] == pytest.approx(0.02)
    assert joints["right"]["mimic"]["multiplier"] == -0.5


def test_leader_not_a_joint_is_reported_and_independent(tmp_path) -> None:
    """A leader that is no joint of the robot (here a body): one report line, as for a URDF."""
    mimic = NEWTON.replace("</bot/left>", "</bot/left_link>")
    joints, lines = _joints(tmp_path, '"NewtonMimicAPI"', mimic)
    assert "mimic" not in joints["right"]
    said = [line for line in lines if "mimic" in line]
    assert len(said) == 1 and "'right' mimics '/bot/left_link'" in said[0]
    assert "independent" in said[0]


def test_no_leader_is_reported_and_independent(tmp_path) -> None:
    joints, lines = _joints(tmp_path, '"NewtonMimicAPI"', "float newton:mimicCoef1 = 2")
    assert "mimic" not in joints["right"]
    said = [line for line in lines if "NewtonMimicAPI" in line]
    assert len(said) == 1 and "0 leader joints" in said[0]


URDF = """<robot name="pinch">
  <link name="palm"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link>
  <link name="a"><inertial><mass value="0.1"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><mass value="0.1"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="lead" type="revolute"><parent link="palm"/><child link="a"/>
    <origin xyz="0 0.3 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-0.5" upper="0.5" effort="5" velocity="1"/></joint>
  <joint name="follow" type="revolute"><parent link="palm"/><child link="b"/>
    <origin xyz="0 -0.3 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="5" velocity="1"/>
    <mimic joint="lead" multiplier="-2" offset="0.25"/></joint>
</robot>
"""


def test_kit_usd_round_trip(tmp_path) -> None:
    """A revolute follower written by simkit's own USD emitter (PhysxMimicJointAPI, gearing
    2, offset -0.25 rad in degrees) imports back with the spec's mimic."""
    from simkit.emit import usd
    from simkit.pipeline import model_from_spec

    urdf = tmp_path / "pinch.urdf"
    urdf.write_text(URDF)
    spec = import_robot(urdf, tmp_path / "spec").spec_path
    robot = model_from_spec(str(spec))
    want = next(j for j in yaml.safe_load(spec.read_text())["joints"] if j["name"] == "follow")
    for rel, data in usd.emit(robot).items():
        (tmp_path / "kit" / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "kit" / rel).write_bytes(data)
    physics = next((tmp_path / "kit").glob("usd/*/payloads/physics.usda")).read_text()
    follow = physics.split('def PhysicsRevoluteJoint "follow"')[1].split("}")[0]
    assert "physxMimicJoint:rotY:gearing = 2" in follow
    assert f"physxMimicJoint:rotY:offset = {-math.degrees(0.25):.4f}"[:-2] in follow
    done = import_robot(tmp_path / "kit" / "usd" / "pinch.usda", tmp_path / "back")
    back = {j["name"]: j for j in yaml.safe_load(done.spec_path.read_text())["joints"]}
    got = back["follow"]["mimic"]
    assert got["joint"] == want["mimic"]["joint"] == "lead"
    assert got["multiplier"] == want["mimic"]["multiplier"] == -2
    assert got["offset"] == pytest.approx(want["mimic"]["offset"], abs=1e-6)
