"""The ECN 2R kit (robots/ecn_2r.yaml, reference 002_e760a3794accbbd5.txt): the report's
inertia tensors in every format, the drive model, the world mounting, ros2_control, the
link_0 inertia decision and the free-fall validation."""

from __future__ import annotations

import ast
import json
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest
import yaml

from simkit.check.freefall import check_freefall
from simkit.check.kit import Kit
from simkit.errors import SpecError
from simkit.model.kinematics import rpy_matrix
from simkit.spec.validate import load_spec

REPO = Path(__file__).resolve().parents[1]
SPEC = (REPO / "robots" / "ecn_2r.yaml").read_text()

# Report 002_e760a3794accbbd5.txt, Figures 7 and 8: mass, CoM, inertia (ixx iyy izz ixy ixz iyz).
REPORT = {
    "link_1": (
        7.084761,
        (0.066529, 0.0, 0.179392),
        (0.147885, 0.196455, 0.055095, 0.0, -0.033179, 0.0),
    ),
    "link_2": (
        3.181291,
        (0.082451, 0.0, 0.045927),
        (0.013725, 0.067471, 0.057501, 0.0, 0.006881, 0.0),
    ),
}
LINK_0_REPORTED = (1.156125, 1.128704, 2.291404, 0.0, 0.0, 0.0)  # Appendix 1
ARMATURE = (38e-6 + 7.7e-6) * 15**2  # (J_motor + J_gear) * ratio^2 = 0.0102825 kg m^2
PEAK = min(4.0 * 15 * 0.94, 70.0)  # N m: 56.4


def _tensor(ixx, iyy, izz, ixy, ixz, iyz) -> np.ndarray:
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


@pytest.fixture(scope="module")
def kit(kit_factory):
    return kit_factory("ecn_2r")


@pytest.fixture(scope="module")
def doc(kit) -> dict:
    return json.loads((kit.kit_dir / "robot.json").read_text())


@pytest.fixture(scope="module")
def urdf(kit) -> ET.Element:
    return ET.parse(kit.kit_dir / "urdf" / "ecn_2r.urdf").getroot()


@pytest.fixture(scope="module")
def mj(kit) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(kit.kit_dir / "mjcf" / "ecn_2r.xml"))


def test_build_passes_its_checks(kit):
    names = {f.check for f in kit.findings}
    assert all(f.ok for f in kit.findings)
    assert {"freefall.rigid.mjcf_vs_independent", "freefall.friction.urdf_vs_independent"} <= names


@pytest.mark.parametrize("link", sorted(REPORT))
def test_inertia_in_urdf_mjcf_and_robot_json(link, doc, urdf, mj, kit):
    mass, com, inertia = REPORT[link]
    el = urdf.find(f"link[@name='{link}']/inertial")
    assert float(el.find("mass").get("value")) == mass
    assert [float(v) for v in el.find("origin").get("xyz").split()] == list(com)
    attrs = el.find("inertia").attrib
    assert tuple(float(attrs[k]) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")) == inertia
    assert float(attrs["ixz"]) != 0.0  # the off-diagonal term survives

    mjcf = ET.parse(kit.kit_dir / "mjcf" / "ecn_2r.xml").getroot()
    body = mjcf.find(f".//body[@name='{link}']/inertial")
    assert tuple(float(v) for v in body.get("fullinertia").split()) == inertia
    # and MuJoCo compiles it into the same full tensor (principal moments and axes)
    b = mj.body(link).id
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, mj.body_iquat[b])
    rot = rot.reshape(3, 3)
    compiled = rot @ np.diag(mj.body_inertia[b]) @ rot.T
    assert np.allclose(compiled, _tensor(*inertia), atol=1e-12)
    assert np.allclose(mj.body_ipos[b], com, atol=1e-12)

    entry = next(e for e in doc["links"] if e["name"] == link)
    assert entry["mass"] == mass and entry["com"] == list(com)
    assert tuple(entry["inertia"][k] for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")) == inertia


def test_drive_armature_and_peak_torque(doc, mj):
    assert pytest.approx(0.0102825, rel=1e-12) == ARMATURE
    for joint in doc["joints"]:
        assert joint["armature"] == pytest.approx(ARMATURE, rel=1e-9)
        assert joint["drive_peak_torque_at_joint"] == pytest.approx(PEAK, rel=1e-9)
        assert joint["drive"]["gear_ratio"] == 15 and joint["drive"]["efficiency"] == 0.94
        assert (joint["effort_peak"], joint["max_velocity"], joint["friction"]) == (100, 10, 0.01)
        assert mj.dof_armature[mj.joint(joint["name"]).dofadr[0]] == pytest.approx(ARMATURE)
        assert mj.actuator(joint["name"]).forcerange[1] == pytest.approx(PEAK)
    j1 = doc["joints"][0]
    assert (j1["lower"], j1["upper"]) == (-3.211405854, 0.0698132)


def test_joint_limits_friction_in_urdf_and_mjcf(urdf, mj):
    """Report section 4: joint_1 limit -3.211405854 .. 0.0698132 rad, effort 100, velocity 10,
    damping 0, friction 0.01, as written in the URDF and the MJCF (not only robot.json)."""
    for name in ("joint_1", "joint_2"):
        joint = urdf.find(f"joint[@name='{name}']")
        limit, dynamics = joint.find("limit").attrib, joint.find("dynamics").attrib
        assert (float(limit["effort"]), float(limit["velocity"])) == (100, 10)
        assert (float(dynamics["damping"]), float(dynamics["friction"])) == (0, 0.01)
        dof = mj.joint(name).dofadr[0]
        assert (mj.dof_damping[dof], mj.dof_frictionloss[dof]) == (0, 0.01)
    limit = urdf.find("joint[@name='joint_1']/limit").attrib
    assert (limit["lower"], limit["upper"]) == ("-3.211405854", "0.0698132")
    assert tuple(mj.joint("joint_1").range) == (-3.211405854, 0.0698132)
    assert mj.jnt_limited[mj.joint("joint_1").id]


def test_world_mounting(doc, urdf, mj):
    """The fixed world joint (report section 4 step 1) puts the joint axes horizontal, so the
    arm swings in a vertical plane; the MJCF has it as base_link's body pose (the report's
    link 0)."""
    joint = urdf.find("joint[@name='world_joint']")
    assert joint.get("type") == "fixed" and joint.find("parent").get("link") == "world"
    assert joint.find("origin").get("xyz") == "0 0 1"
    assert [float(v) for v in joint.find("origin").get("rpy").split()] == pytest.approx(
        [np.pi / 2, -np.pi / 2, 0.0], abs=1e-9
    )
    data = mujoco.MjData(mj)
    mujoco.mj_forward(mj, data)
    body = data.body("base_link")  # the report's link 0
    assert np.allclose(body.xpos, [0, 0, 1.0])
    assert np.allclose(body.xmat.reshape(3, 3), rpy_matrix((np.pi / 2, -np.pi / 2, 0)), atol=1e-9)
    axis = data.xaxis[mj.joint("joint_1").id]
    assert abs(axis[2]) < 1e-9  # horizontal: gravity acts in the plane of motion
    assert abs(data.qfrc_bias[0]) > 1.0  # the arm pointing sideways at q = 0 feels gravity
    fixed = {j["name"]: j for j in doc["fixed_joints"]}
    assert fixed["world_joint"]["origin_xyz"] == [0.0, 0.0, 1.0]


def test_link_0_inertia_decision_is_recorded(doc, urdf):
    entry = doc["links"][0]
    decision = entry["inertia_decision"]
    assert entry["name"] == "base_link" and decision["action"] == "exclude_from_dynamics"
    reported = tuple(decision["reported"][k] for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz"))
    assert reported == LINK_0_REPORTED
    assert "triangle inequality" in decision["problem"] and decision["reason"]
    mean = sum(LINK_0_REPORTED[:3]) / 3
    assert [decision["emitted"][k] for k in ("ixx", "iyy", "izz")] == pytest.approx([mean] * 3)
    assert entry["inertia"]["izz"] == pytest.approx(mean)  # what the files carry
    assert entry["mass"] == 15.136597
    attrs = urdf.find("link[@name='base_link']/inertial/inertia").attrib
    assert float(attrs["izz"]) == pytest.approx(mean)


def _without_decision() -> str:
    text = re.sub(r"    inertia_decision:\n(?:      .*\n|        .*\n)+", "", SPEC)
    assert "inertia_decision" not in text
    return text


@pytest.mark.slow
def test_spec_without_the_decision_fails_in_one_line(tmp_path):
    path = tmp_path / "ecn_2r_nodecision.yaml"
    path.write_text(_without_decision())
    with pytest.raises(SpecError) as err:
        load_spec(path)
    line = next(i for i, t in enumerate(path.read_text().splitlines(), 1) if "izz: 2.291404" in t)
    assert err.value.line == line and err.value.field == "links[0].inertia"
    assert "triangle inequality" in str(err.value) and "\n" not in str(err.value)
    run = subprocess.run(
        [
            sys.executable,
            "-m",
            "simkit.cli",
            "build",
            "-q",
            str(path),
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and "triangle inequality" in run.stderr
    assert not (tmp_path / "out" / "ecn_2r_description").exists()


def test_decision_rules(tmp_path):
    """exclude_from_dynamics only for a link welded to the world; a decision on a physical
    tensor is stale; `balance` may keep a moving link's tensor."""
    bad_link_2 = "{ixx: 0.013725, iyy: 0.067471, izz: 0.057501, ixy: 0.0, ixz: 0.006881, iyz: 0.0}"
    broken = "{ixx: 0.01, iyy: 0.01, izz: 0.05, ixy: 0.0, ixz: 0.0, iyz: 0.0}"
    decision = "\n    inertia_decision: {action: %s, reason: test}"
    cases = {
        "exclude": (broken + decision % "exclude_from_dynamics", "moves"),
        "stale": (bad_link_2 + decision % "balance", "the inertia is physical"),
        "balance": (broken + decision % "balance", None),
    }
    for name, (replacement, message) in cases.items():
        path = tmp_path / f"{name}.yaml"
        path.write_text(SPEC.replace(bad_link_2, replacement))
        if message is None:
            assert load_spec(path)[0].links[2].inertia_decision.action == "balance"
        else:
            with pytest.raises(SpecError, match=message):
                load_spec(path)


def test_ros2_control_in_urdf(urdf):
    control = urdf.find("ros2_control")
    assert control.find("hardware/plugin").text == "gz_ros2_control/GazeboSimSystem"
    for name in ("joint_1", "joint_2"):
        joint = control.find(f"joint[@name='{name}']")
        assert [c.get("name") for c in joint.findall("command_interface")] == ["position", "effort"]
        assert [s.get("name") for s in joint.findall("state_interface")] == [
            "position",
            "velocity",
            "effort",
        ]
    plugin = urdf.find("gazebo/plugin")
    assert plugin.get("filename") == "gz_ros2_control-system"
    assert plugin.find("parameters").text.endswith("/config/controllers.yaml")
    colours = {
        g.get("reference"): g.find("material").text for g in urdf.findall("gazebo[@reference]")
    }
    assert colours == {"link_1": "Gazebo/Turquoise", "link_2": "Gazebo/Orange"}
    # URDF transmission spec (the reduction on the actuator); yourdfpy 0.0.5x drops
    # mechanicalReduction when parsing, so read the XML
    reductions = {
        t.find("joint").get("name"): float(t.find("actuator/mechanicalReduction").text)
        for t in urdf.findall("transmission")
        if t.find("type").text == "transmission_interface/SimpleTransmission"
    }
    assert reductions == {"joint_1": 15.0, "joint_2": 15.0}


def test_controllers_and_gazebo_launch(kit, doc):
    config = yaml.safe_load((kit.kit_dir / "config" / "controllers.yaml").read_text())
    types = config["controller_manager"]["ros__parameters"]
    assert (
        types["joint_state_broadcaster"]["type"] == "joint_state_broadcaster/JointStateBroadcaster"
    )
    # the report's controller names (002_e760a3794accbbd5.txt section 5): joint1_..., joint2_...
    for name, stem in (("joint_1", "joint1"), ("joint_2", "joint2")):
        assert types[f"{stem}_position_controller"]["type"] == "pid_controller/PidController"
        assert types[f"{stem}_effort_controller"]["type"] == (
            "effort_controllers/JointGroupEffortController"
        )
        gains = config[f"{stem}_position_controller"]["ros__parameters"]["gains"][name]
        assert gains == {
            "p": 200.0,
            "i": 0.01,
            "d": 10.0,
            "i_clamp_max": 40.0,
            "i_clamp_min": -40.0,
            "antiwindup": True,
        }
        assert all(isinstance(gains[k], float) for k in ("p", "d", "i_clamp_max"))  # ROS doubles
    launch = (kit.kit_dir / "launch" / "gazebo.launch.py").read_text()
    tree = ast.parse(launch)
    assert "generate_launch_description" in {
        f.name for f in tree.body if isinstance(f, ast.FunctionDef)
    }
    assert (kit.kit_dir / "launch" / "display.launch.py").is_file()
    package = (kit.kit_dir / "package.xml").read_text()
    assert "<exec_depend>gz_ros2_control</exec_depend>" in package
    record = doc["ros2_control"]
    assert record["transmissions"] == {"joint_1": 15.0, "joint_2": 15.0}
    assert record["position_pid"]["p"] == 200.0 and record["estimated"] == ["update_rate"]


def test_freefall_figures_and_plot(doc, kit):
    record = doc["validation"]["freefall"]
    assert record["duration"] == 2.0 and record["tolerance_rms"] == 1e-3 and record["passed"]
    for run in ("rigid", "friction"):
        for pair in ("mjcf_vs_independent", "urdf_vs_independent", "mjcf_vs_urdf"):
            assert record["runs"][run][pair]["rms"] < 1e-3
    assert record["runs"]["rigid"]["mjcf_vs_independent"]["rms"] < 1e-6  # same model, no friction
    png = (kit.kit_dir / "validation" / "freefall.png").read_bytes()
    assert png.startswith(b"\x89PNG") and b"Software" not in png and b"tIME" not in png
    header = (kit.kit_dir / "validation" / "freefall.csv").read_text().splitlines()[0]
    assert "friction.independent.joint_2" in header and "rigid.urdf.joint_1" in header


def test_freefall_check_fails_when_a_model_drifts(kit, tmp_path):
    """Scale link_2's inertia in the MJCF only: MJCF and the others drift apart, check fails."""
    copy = tmp_path / "kit"
    shutil.copytree(kit.kit_dir, copy)
    mjcf = copy / "mjcf" / "ecn_2r.xml"
    text = mjcf.read_text()
    old = 'mass="3.181291"'
    assert old in text
    mjcf.write_text(text.replace(old, 'mass="3.3"'))
    failed = {f.check for f in check_freefall(Kit.open(copy)) if not f.ok}
    assert "freefall.rigid.mjcf_vs_independent" in failed
    assert "freefall.rigid.mjcf_vs_urdf" in failed
    assert "freefall.rigid.urdf_vs_independent" not in failed
