"""The kit page's published numbers, exact in every output, for all three Rosie arms."""

from __future__ import annotations

import itertools
import json
import re
from pathlib import Path

import mujoco
import numpy as np
import pytest
import yaml
import yourdfpy

from mjcompat import full_mass_matrix
from simkit.model.dynamics import gravity_torques
from simkit.pipeline import model_from_spec

# Kit page (000_5f76ade803e16979.txt), table "Robot | Wrist centre | Published reach | tool0 at
# home | Mass" and "Frames and conventions".
PUBLISHED = {
    "rosie_600": dict(
        wrist=0.6000, reach=(0.600, 0.677), tool0=(0.330, 0, 0.423), height=0.175, mass=29.3
    ),
    "rosie_1000": dict(
        wrist=1.0000, reach=(1.000, 1.077), tool0=(0.530, 0, 0.623), height=0.175, mass=38.6
    ),
    "rosie_1400": dict(
        wrist=1.4337, reach=(1.400, 1.499), tool0=(0.834, 0, 0.756), height=0.0294, mass=77.0
    ),
}
JOINTS = [f"J{i}" for i in range(1, 7)]  # kit page: J1 to J6
REPO = Path(__file__).resolve().parents[1]
MM = 1e-4  # 0.1 mm
KG = 0.01
AXES = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]


@pytest.fixture(scope="module", params=sorted(PUBLISHED))
def kit(request, kit_factory):
    return request.param, kit_factory(request.param)


def _mj_tool0(model, q):
    data = mujoco.MjData(model)
    data.qpos[:6] = q
    mujoco.mj_forward(model, data)
    base = data.body("base_link")
    rot = base.xmat.reshape(3, 3)
    return rot.T @ (data.site("tool0").xpos - base.xpos), rot.T @ data.site("tool0").xmat.reshape(
        3, 3
    )


def test_robot_json_numbers(kit):
    name, result = kit
    pub = PUBLISHED[name]
    doc = json.loads((result.kit_dir / "robot.json").read_text())
    assert [j["axis"] for j in doc["joints"]] == [list(map(float, a)) for a in AXES]
    assert abs(doc["frames"]["base_link"]["height"] - pub["height"]) < MM
    assert abs(sum(link["mass"] for link in doc["links"]) - pub["mass"]) < KG
    assert abs(doc["mass"]["published"] - pub["mass"]) < KG
    assert abs(doc["reach"]["geometric"]["wrist"] - pub["wrist"]) < MM
    assert doc["reach"]["published"] == {"wrist": pub["reach"][0], "flange": pub["reach"][1]}
    home = next(r for r in doc["fk_reference"] if r["pose"] == "home")
    np.testing.assert_allclose(home["tool0"]["xyz"], pub["tool0"], atol=MM)
    # every joint origin is a pure translation; zero pose is home
    assert all(j["origin_rpy"] == [0.0, 0.0, 0.0] for j in doc["joints"])
    assert doc["home"] == [0.0] * 6


def test_mjcf_numbers(kit):
    name, result = kit
    pub = PUBLISHED[name]
    model = mujoco.MjModel.from_xml_path(str(result.kit_dir / f"mjcf/{name}.xml"))
    pos, rot = _mj_tool0(model, np.zeros(6))
    np.testing.assert_allclose(pos, pub["tool0"], atol=MM)
    # tool0: z out of the flange (down at home), x along base +x
    np.testing.assert_allclose(rot, np.diag([1, -1, -1]), atol=1e-9)
    data = mujoco.MjData(model)
    data.qpos[:6] = np.radians([0, 90, -90, 0, 0, 0])
    mujoco.mj_forward(model, data)
    base = data.body("base_link").xpos
    wrist = data.body("link_5").xpos - base
    assert abs(np.hypot(wrist[0], wrist[1]) - pub["wrist"]) < MM
    assert abs(model.body_mass.sum() - pub["mass"]) < KG
    assert abs(base[2] - pub["height"]) < MM
    for i, axis in enumerate(AXES):
        np.testing.assert_allclose(model.jnt_axis[i], axis)


def test_urdf_numbers(kit):
    name, result = kit
    pub = PUBLISHED[name]
    urdf = yourdfpy.URDF.load(str(result.kit_dir / f"urdf/{name}.urdf"), load_meshes=False)
    assert urdf.base_link == "base_footprint"
    T = urdf.get_transform("tool0", "base_link")
    np.testing.assert_allclose(T[:3, 3], pub["tool0"], atol=MM)
    # tool0: z out of the flange (down at home), x along base +x
    np.testing.assert_allclose(T[:3, :3], np.diag([1, -1, -1]), atol=1e-9)
    assert abs(urdf.get_transform("base_link", "base_footprint")[2, 3] - pub["height"]) < MM
    mass = sum(link.inertial.mass for link in urdf.robot.links if link.inertial is not None)
    assert abs(mass - pub["mass"]) < KG
    urdf.update_cfg(dict(zip(JOINTS, np.radians([0, 90, -90, 0, 0, 0]), strict=True)))
    wrist = urdf.get_transform("link_5", "base_link")[:3, 3]
    assert abs(np.hypot(wrist[0], wrist[1]) - pub["wrist"]) < MM


def _spec_joints(name: str) -> list[dict]:
    """The movable joints as the spec file states them (independent of the pipeline)."""
    doc = yaml.safe_load((REPO / "robots" / f"{name}.yaml").read_text())
    return [j for j in doc["joints"] if j.get("type", "revolute") == "revolute"]


def test_urdf_simulation_parameters(kit):
    """Kit page, "Simulation parameters": URDF effort = effort_peak, velocity = the maximum
    joint speed; mesh paths relative to the file (../meshes/)."""
    name, result = kit
    text = (result.kit_dir / f"urdf/{name}.urdf").read_text()
    urdf = yourdfpy.URDF.load(str(result.kit_dir / f"urdf/{name}.urdf"), load_meshes=False)
    joints = {j.name: j for j in urdf.robot.joints}
    for spec in _spec_joints(name):
        limit = joints[spec["name"]].limit
        assert limit.effort == pytest.approx(spec["effort_peak"], rel=1e-9), spec["name"]
        speed = np.radians(spec["max_velocity_deg_s"])
        assert limit.velocity == pytest.approx(speed, rel=1e-9), spec["name"]
        assert limit.lower == pytest.approx(np.radians(spec["lower_deg"]), rel=1e-9)
        assert limit.upper == pytest.approx(np.radians(spec["upper_deg"]), rel=1e-9)
    meshes = re.findall(r'filename="([^"]+)"', text)
    assert meshes and all(m.startswith("../meshes/") for m in meshes)
    assert all((result.kit_dir / "urdf" / m).is_file() for m in meshes)


def test_mjcf_simulation_parameters(kit):
    """Kit page, "Simulation parameters": position servos with ctrl in radians, kp =
    effort_peak per 0.01 rad, critically damped (kv = 2 sqrt(kp M_ii) with MuJoCo's own mass
    matrix at home, armature included), forcerange = drive_peak_torque_at_joint (motor peak x
    ratio), armature = reflected rotor inertia, damping from the spec; site tool0; collisions
    excluded between adjacent links only."""
    name, result = kit
    model = mujoco.MjModel.from_xml_path(str(result.kit_dir / f"mjcf/{name}.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    full = full_mass_matrix(model, data)
    assert model.nu == 6
    for i, spec in enumerate(_spec_joints(name)):
        act = model.actuator(spec["name"])
        joint = model.joint(spec["name"])
        assert model.actuator_trnid[act.id, 0] == joint.id
        kp = spec["effort_peak"] / 0.01
        assert act.gainprm[0] == pytest.approx(kp, rel=1e-9)
        assert tuple(act.biasprm[:2]) == pytest.approx((0.0, -kp), rel=1e-9)
        dof = model.jnt_dofadr[joint.id]
        assert -act.biasprm[2] == pytest.approx(2 * np.sqrt(kp * full[dof, dof]), rel=1e-8)
        drive = spec["drive"]
        peak = drive["motor_peak_torque"] * drive["gear_ratio"]
        assert peak >= spec["effort_peak"]
        assert tuple(act.forcerange) == pytest.approx((-peak, peak), rel=1e-9)
        limits = np.radians([spec["lower_deg"], spec["upper_deg"]])
        assert tuple(act.ctrlrange) == pytest.approx(tuple(limits), rel=1e-9)
        assert tuple(model.jnt_range[joint.id]) == pytest.approx(tuple(limits), rel=1e-9)
        armature = drive["rotor_inertia"] * drive["gear_ratio"] ** 2
        assert model.dof_armature[dof] == pytest.approx(armature, rel=1e-9)
        assert model.dof_damping[dof] == pytest.approx(spec["damping"], rel=1e-9)
        assert i == dof
    assert model.site("tool0").id >= 0
    bodies = ["base_link", *[f"link_{i}" for i in range(1, 7)]]
    excluded = {
        tuple(sorted((model.body(s >> 16).name, model.body(s & 0xFFFF).name)))
        for s in model.exclude_signature
    }
    assert excluded == {tuple(sorted(pair)) for pair in itertools.pairwise(bodies)}


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_peak_torque_holds_rated_payload_when_stretched(name):
    robot = model_from_spec(name)
    payload = robot.published["payload"]
    tool = np.eye(3) * 1e-6
    torques = gravity_torques(
        robot, robot.pose("stretched"), extra=[("link_6", payload, (0.0, 0.0, -0.05), tool)]
    )
    for joint in robot.movable_joints:
        assert abs(torques[joint.name]) < joint.effort_peak, joint.name
        assert joint.effort_peak <= joint.drive_peak_torque_at_joint + 1e-9, joint.name
    assert "payload" in robot.published_estimated


def test_unpublished_values_are_marked_estimated(kit):
    """The page publishes only sums of the joint offsets (tool0 at home, wrist reach, flange
    offset), no link masses, limits, speeds, torques, drives or payload: robot.json marks
    every such value as an estimate."""
    _name, result = kit
    doc = json.loads((result.kit_dir / "robot.json").read_text())
    assert all("mass" in link["estimated"] for link in doc["links"])
    joints = {j["name"]: set(j["estimated"]) for j in doc["joints"]}
    for name, estimated in joints.items():
        assert {"lower_deg", "upper_deg", "max_velocity_deg_s", "effort_peak"} <= estimated
        assert {"effort_continuous", "drive"} <= estimated, name
        # J3 (upper arm) and J6 (flange) follow from the published figures; the splits of the
        # J1/J2 heights and of the forearm between J4 and J5 do not
        assert ("xyz" in estimated) == (name in ("J1", "J2", "J4", "J5"))
    assert {"payload", "repeatability_mm"} <= set(doc["provenance"]["published_estimated"])
