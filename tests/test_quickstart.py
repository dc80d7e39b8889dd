"""The kit page's quickstart snippets, run from inside a built kit with only the file location
changed (robot.json is read from the kit instead of the web)."""

from __future__ import annotations

import ast
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from page_snippets import IK_CASES_SNIPPET

MUJOCO_SNIPPET = """
import mujoco
import numpy as np
model = mujoco.MjModel.from_xml_path("mjcf/rosie_1000.xml")
data = mujoco.MjData(model)
data.ctrl[:] = np.radians([30, 45, -10, 0, -35, 0]) # position servos on J1..J6
for _ in range(1500): # 3 s at 2 ms steps
    mujoco.mj_step(model, data)
print(np.degrees(data.qpos).round(2)) # joint angles (deg)
print(data.actuator_force.round(1)) # joint torques (N m)
print(data.site("tool0").xpos.round(4)) # flange face (m)
"""

PYBULLET_SNIPPET = """
import math
import pybullet as p
p.connect(p.DIRECT) # p.GUI for a window
p.setGravity(0, 0, -9.81)
robot = p.loadURDF("urdf/rosie_1000.urdf", useFixedBase=True,
flags=p.URDF_USE_INERTIA_FROM_FILE)
joints = [p.getJointInfo(robot, i) for i in range(p.getNumJoints(robot))]
arm = [j for j in joints if j[2] == p.JOINT_REVOLUTE] # J1..J6
tool0 = next(j[0] for j in joints if j[12] == b"tool0")
target = [math.radians(a) for a in (30, 45, -10, 0, -35, 0)]
for j, q in zip(arm, target): # j[10] peak torque, j[11] max speed
    p.setJointMotorControl2(robot, j[0], p.POSITION_CONTROL, targetPosition=q,
force=j[10], maxVelocity=j[11])
for _ in range(3 * 240):
    p.stepSimulation()
print(p.getLinkState(robot, tool0, computeForwardKinematics=True)[4])
"""

FK_SNIPPET = """
import json
import numpy as np
robot = json.load(open("robot.json"))
def rot(axis, q):
    x, y, z = axis
    c, s, t = np.cos(q), np.sin(q), 1 - np.cos(q)
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
[t * x * y + s * z, t * y * y + c, t * y * z - s * x],
[t * x * z - s * y, t * y * z + s * x, t * z * z + c]])
def fk(q):
    \"\"\"Pose of tool0 (4x4) in base_link for joint angles q (rad).\"\"\"
    T = np.eye(4)
    for j, qi in zip(robot["joints"], q):
        A = np.eye(4)
        A[:3, 3], A[:3, :3] = j["origin_xyz"], rot(j["axis"], qi)
        T = T @ A
    return T @ np.diag([1, -1, -1, 1]) # tool0: z out of the flange
print(fk(robot["poses"]["stretched"])[:3, 3]) # (m)
print(fk(robot["home"])[:3, 3])
"""


def _words(code: str) -> list[str]:
    """Code lines with whitespace collapsed, blank lines dropped: the page's text lost its
    indentation of continuation lines and comment spacing, the README has PEP 8's."""
    return [" ".join(line.split()) for line in code.splitlines() if line.strip()]


def _run(kit_dir, code: str) -> list[str]:
    proc = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        cwd=kit_dir,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    return proc.stdout.strip().splitlines()


def _floats(line: str) -> np.ndarray:
    return np.array([float(v) for v in line.strip("[]() ").replace(",", " ").split()])


def test_mujoco_snippet(rosie_1000):
    out = _run(rosie_1000.kit_dir, MUJOCO_SNIPPET)
    q = _floats(out[0])
    np.testing.assert_allclose(q, [30, 45, -10, 0, -35, 0], atol=0.5)  # servos reach the target
    torques = _floats(out[1])
    assert np.abs(torques).max() > 1.0  # gravity is being held
    assert _floats(out[2]).shape == (3,)


def test_pybullet_snippet(rosie_1000):
    out = _run(rosie_1000.kit_dir, PYBULLET_SNIPPET)
    # pybullet may print its own notices on the same line; the tuple is the last thing printed
    pos = _floats(out[-1][out[-1].rindex("(") :])
    # compare with MuJoCo's tool0 at the same joint angles (world frame, base_footprint = origin)
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(rosie_1000.kit_dir / "mjcf/rosie_1000.xml"))
    data = mujoco.MjData(model)
    data.qpos[:] = np.radians([30, 45, -10, 0, -35, 0])
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(pos, data.site("tool0").xpos, atol=0.01)


def test_robot_json_fk_snippet(rosie_1000):
    out = _run(rosie_1000.kit_dir, FK_SNIPPET)
    np.testing.assert_allclose(_floats(out[0]), [1.077, 0.0, 0.230], atol=1e-4)
    np.testing.assert_allclose(_floats(out[1]), [0.530, 0.0, 0.623], atol=1e-4)


def test_pybullet_sees_no_phantom_mass_on_frames(rosie_1000):
    """PyBullet gives a URDF link without <inertial> 1 kg; tool0 must weigh nothing."""
    code = """
import pybullet as p
p.connect(p.DIRECT)
robot = p.loadURDF("urdf/rosie_1000.urdf", useFixedBase=True, flags=p.URDF_USE_INERTIA_FROM_FILE)
masses = {p.getJointInfo(robot, i)[12].decode(): p.getDynamicsInfo(robot, i)[0]
          for i in range(p.getNumJoints(robot))}
print("MASSES", sorted(masses.items()))
"""
    line = next(x for x in _run(rosie_1000.kit_dir, code) if "MASSES" in x)
    masses = dict(ast.literal_eval(line[line.index("[") :]))
    assert masses["tool0"] == 0.0
    assert abs(sum(masses.values()) - 38.6) < 1e-9  # exactly the robot mass


@pytest.mark.slow
def test_ik_cases_snippet(rosie_1000):
    out = _run(rosie_1000.kit_dir, IK_CASES_SNIPPET)
    count, worst, tolerance = out[-1].split()[0], float(out[-1].split()[4]), out[-1].split()[-1]
    assert count == "12" and worst < float(tolerance)


@pytest.mark.slow
@pytest.mark.parametrize("robot", ["rosie_600", "rosie_1000", "rosie_1400"])
def test_readme_carries_the_page_snippets(kit_factory, robot):
    """The kit README's quickstart is the kit page's, apart from the file location (and the
    model number, as the page says: "change 1000 to 600 or 1400")."""
    readme = _words((kit_factory(robot).kit_dir / "README.md").read_text())
    model = robot.split("_")[1]
    fk_local = [line for line in _words(FK_SNIPPET) if 'robot["home"]' not in line]
    for snippet in (MUJOCO_SNIPPET, PYBULLET_SNIPPET, IK_CASES_SNIPPET, "\n".join(fk_local)):
        lines = [line.replace("rosie_1000", f"rosie_{model}") for line in _words(snippet)]
        found = any(readme[i : i + len(lines)] == lines for i in range(len(readme)))
        assert found, f"README lacks the page snippet starting {lines[0]!r}"
    text = " ".join(readme)
    for pointer in (
        "examples/fk_ik.py",
        "ik_cases.json",
        "benchmark/",
        f"glb/rosie_{model}.glb",
        "usd/",
    ):
        assert pointer in text
