"""The kit's examples/ scripts run from inside a built kit with only their own imports."""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest


def _run(kit, script: str) -> str:
    done = subprocess.run(
        [sys.executable, f"examples/{script}"], cwd=kit, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def _tool(text: str) -> np.ndarray:
    match = re.search(r"tool0 position \(m\): \[([^\]]*)\]", text)
    assert match, text
    return np.array([float(v) for v in match.group(1).split()])


def _error_deg(text: str) -> float:
    return float(re.search(r"max \|q - target\| \(deg\): ([0-9.]+)", text).group(1))


def test_mujoco_and_pybullet_demos_reach_the_work_pose(rosie_1000):
    pytest.importorskip("pybullet")
    kit = rosie_1000.kit_dir
    mujoco_out = _run(kit, "mujoco_demo.py")
    pybullet_out = _run(kit, "pybullet_demo.py")
    # Servos hold the pose within a few tenths of a degree (kit page, Simulation parameters).
    assert _error_deg(mujoco_out) < 0.5
    assert _error_deg(pybullet_out) < 0.5
    assert "joint torques (N m)" in mujoco_out
    # Both simulators put tool0 in the same place (world frame, m).
    assert np.abs(_tool(mujoco_out) - _tool(pybullet_out)).max() < 0.005


def test_fk_ik_example_runs_if_present(rosie_1000):
    kit = rosie_1000.kit_dir
    if not (kit / "examples" / "fk_ik.py").is_file():
        pytest.skip("examples/fk_ik.py comes with the motion-data emitter")
    _run(kit, "fk_ik.py")
