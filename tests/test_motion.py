"""Derived accelerations and robot.json's `motion` block (kit page, 000_5f76ade803e16979.txt,
"Accelerations and motion profiles")."""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest

from simkit.emit import motion_files, robot_json
from simkit.model.kinematics import axis_angle, quat_wxyz, rpy_matrix, transform
from simkit.model.robot import SimReports
from simkit.pipeline import model_from_spec

STEP = 1e-5  # s, finite-difference time step
STEPS = 10


@pytest.fixture(scope="module")
def doc(rosie_1000) -> dict:
    return json.loads((rosie_1000.kit_dir / "robot.json").read_text(encoding="utf-8"))


def _vec(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def _quat_rotation(text: str | None) -> np.ndarray:
    if not text:
        return np.eye(3)
    w, x, y, z = (float(v) for v in text.split())
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _locked_model(mjcf: Path, free: str, q: dict, payload: dict, tool: dict) -> mujoco.MjModel:
    """The kit's MJCF with every joint but `free` welded at its pose q, no geometry, no
    servos, and the payload as one body on the tool frame's parent."""
    root = ET.parse(mjcf).getroot()
    for parent in list(root.iter()):
        for child in list(parent):
            if child.tag in ("geom", "actuator") or (child.tag == "mesh" and parent.tag == "asset"):
                parent.remove(child)
            elif child.tag == "joint" and child.get("name") != free:
                axis = [float(v) for v in child.get("axis").split()]
                rot = _quat_rotation(parent.get("quat")) @ axis_angle(axis, q[child.get("name")])
                parent.set("quat", _vec(quat_wxyz(rot)))
                parent.remove(child)
    body = next(b for b in root.iter("body") if b.get("name") == tool["parent"])
    com = transform(tool["xyz"], rpy_matrix(tool["rpy"])) @ np.array([*payload["com_xyz"], 1.0])
    holder = ET.SubElement(body, "body", name="payload", pos=_vec(com[:3]))
    ET.SubElement(
        holder,
        "inertial",
        pos="0 0 0",
        mass=_vec([payload["mass"]]),
        diaginertia=_vec(payload["inertia_diag"]),
    )
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    model.opt.timestep = STEP
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    return model


@pytest.mark.parametrize("name", ["rosie_600", "rosie_1000", "rosie_1400"])
@pytest.mark.parametrize("case", ["stretched_rated_payload", "work_1kg"])
def test_derived_acceleration_matches_mujoco_finite_difference(kit_factory, name, case):
    """Peak torque against gravity on one joint, the others held: the velocity MuJoCo
    integrates over 0.1 ms gives the acceleration within 1 %, for each arm."""
    kit_dir = kit_factory(name).kit_dir
    doc = json.loads((kit_dir / "robot.json").read_text(encoding="utf-8"))
    block = doc["motion"]["derived_max_acceleration"]
    entry = block[case]
    names = block["joints"]
    q = dict(zip(names, entry["q"], strict=True))
    joints = {j["name"]: j for j in doc["joints"]}
    mjcf = kit_dir / doc["files"]["mjcf"]
    for name, expected in zip(names, entry["rad_s2"], strict=True):
        model = _locked_model(mjcf, name, q, entry["payload"], doc["frames"]["tool0"])
        data = mujoco.MjData(model)
        data.qpos[0] = q[name]
        mujoco.mj_forward(model, data)
        hold = float(data.qfrc_bias[0])  # gravity torque at standstill
        data.qfrc_applied[0] = math.copysign(joints[name]["effort_peak"], hold or 1.0)
        for _ in range(STEPS):
            mujoco.mj_step(model, data)
        measured = abs(float(data.qvel[0])) / (STEPS * STEP)
        assert measured == pytest.approx(expected, rel=0.01), name


def test_payload_model_follows_the_page(doc):
    """Kit page, "Benchmark cycle" (Payload), used by the accelerations too: CoM 100 mm out
    along the tool axis and 50 mm off it, inertia of a uniform 100 mm cube."""
    block = doc["motion"]["derived_max_acceleration"]
    for key, mass in (("stretched_rated_payload", doc["payload"]["rated"]), ("work_1kg", 1.0)):
        payload = block[key]["payload"]
        assert payload["mass"] == mass and payload["frame"] == "tool0"
        x, y, z = payload["com_xyz"]
        assert z == pytest.approx(0.100) and math.hypot(x, y) == pytest.approx(0.050)
        assert payload["inertia_diag"] == pytest.approx([mass * 0.1**2 / 6] * 3)


def test_joints_carry_the_stretched_rated_payload_values(doc):
    block = doc["motion"]["derived_max_acceleration"]
    stretched = block["stretched_rated_payload"]
    assert stretched["pose"] == "stretched" and stretched["q"] == doc["poses"]["stretched"]
    assert stretched["payload_kg"] == doc["payload"]["rated"]
    assert block["work_1kg"]["payload_kg"] == 1 and block["work_1kg"]["q"] == doc["poses"]["work"]
    for joint, rad, deg in zip(
        doc["joints"], stretched["rad_s2"], stretched["deg_s2"], strict=True
    ):
        assert joint["derived_max_acceleration"] == rad > 0
        assert joint["derived_max_acceleration_deg_s2"] == pytest.approx(math.degrees(rad))
        assert deg == pytest.approx(math.degrees(rad))
        # the formula by hand from the recorded terms
        i = doc["joints"].index(joint)
        inertia = stretched["armature"][i] + stretched["axis_inertia"][i]
        assert rad == pytest.approx(
            (joint["effort_peak"] - stretched["gravity_torque"][i]) / inertia
        )


def test_motion_profiles_and_jerk(doc):
    motion = doc["motion"]
    assert "cubic" in motion["profiles"]["programs"]["type"]
    assert "B-spline" in motion["profiles"]["programs"]["free_space"]
    assert "Hermite" in motion["profiles"]["programs"]["welds"]
    assert motion["profiles"]["jog_stop_move_to"]["type"].startswith("double-S")
    assert motion["profiles"]["benchmark"]["type"] == "trapezoid"
    assert motion["jerk"]["per_joint_limit"] is None
    # RosieOS bounds jerk at 2 x the acceleration setting / 0.2 s
    assert motion["jerk"]["planner_bound_at_limit"] == pytest.approx(
        [2 * a / 0.2 for a in motion["acceleration"]["limit"]]
    )


def test_robots_without_a_6r_arm_get_no_motion_products():
    robot = model_from_spec(str(Path(__file__).parent / "specs" / "planar_2r.yaml"))
    doc = robot_json.document(robot, SimReports())
    assert not {"motion", "benchmarks", "ik_reference"} & set(doc)
    assert all("derived_max_acceleration" not in j for j in doc["joints"])
    assert motion_files.emit(robot) == {}
