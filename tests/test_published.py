"""The kit page's published numbers, exact in every output, for all three Rosie arms."""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest
import yourdfpy

from simkit.build import model_from_spec
from simkit.dynamics import gravity_torques

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
    assert abs(urdf.get_transform("base_link", "base_footprint")[2, 3] - pub["height"]) < MM
    mass = sum(link.inertial.mass for link in urdf.robot.links if link.inertial is not None)
    assert abs(mass - pub["mass"]) < KG
    for joint in urdf.robot.joints:
        if joint.type == "revolute":
            assert joint.limit.effort > 0 and joint.limit.velocity > 0
            assert "../meshes/" in (result.kit_dir / f"urdf/{name}.urdf").read_text()


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
