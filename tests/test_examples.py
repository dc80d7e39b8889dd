"""The kit's examples/ scripts run from inside a built kit with only their own imports."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest


def _only(tmp_path_factory, *modules: str) -> Path:
    """A folder holding only `modules` (links to the installed ones, and their bundled
    `.libs`): with `python -S` and PYTHONPATH set to it, nothing else is importable beyond
    the standard library, as on a machine with only these packages installed."""
    folder = tmp_path_factory.mktemp("only_" + "_".join(modules))
    for name in modules:
        found = importlib.util.find_spec(name)
        if found is None:
            pytest.skip(f"{name} is not installed")
        origin = Path(found.origin)
        target = origin.parent if found.submodule_search_locations else origin
        (folder / target.name).symlink_to(target)
        libs = target.parent / f"{name}.libs"
        if libs.is_dir():
            (folder / libs.name).symlink_to(libs)
    return folder


def _run(kit, script: str, path: Path) -> str:
    env = {**os.environ, "PYTHONPATH": str(path), "PYTHONNOUSERSITE": "1"}
    done = subprocess.run(
        [sys.executable, "-S", f"examples/{script}"],
        cwd=kit,
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def _tool(text: str) -> np.ndarray:
    match = re.search(r"tool0 position \(m\): \[([^\]]*)\]", text)
    assert match, text
    return np.array([float(v) for v in match.group(1).split()])


def _error_deg(text: str) -> float:
    return float(re.search(r"max \|q - target\| \(deg\): ([0-9.]+)", text).group(1))


def test_mujoco_and_pybullet_demos_reach_the_work_pose(rosie_1000, tmp_path_factory):
    kit = rosie_1000.kit_dir
    mujoco_out = _run(kit, "mujoco_demo.py", _only(tmp_path_factory, "numpy", "mujoco"))
    pybullet_out = _run(kit, "pybullet_demo.py", _only(tmp_path_factory, "numpy", "pybullet"))
    # Servos hold the pose within a few tenths of a degree (kit page, Simulation parameters).
    assert _error_deg(mujoco_out) < 0.5
    assert _error_deg(pybullet_out) < 0.5
    assert "joint torques (N m)" in mujoco_out
    # Both simulators put tool0 in the same place (world frame, m).
    assert np.abs(_tool(mujoco_out) - _tool(pybullet_out)).max() < 0.005


def test_fk_ik_example_with_numpy_alone(rosie_1000, tmp_path_factory):
    """examples/fk_ik.py (an arm kit has one): FK of every reference pose equals robot.json's,
    and the DLS solver reaches all twelve IK cases from their seeds."""
    kit = rosie_1000.kit_dir
    assert (kit / "examples" / "fk_ik.py").is_file()
    text = _run(kit, "fk_ik.py", _only(tmp_path_factory, "numpy"))
    fk = re.findall(r"FK +(\w+): tool0 at \[([^\]]*)\] m \(robot.json: \[([^\]]*)\]\)", text)
    assert {name for name, _, _ in fk} == {"home", "work", "stretched"}, text
    for _, mine, reference in fk:
        assert np.allclose([float(v) for v in mine.split()], [float(v) for v in reference.split()])
    ik = re.findall(r"IK case_\d+: converged (\w+), .* max \|q - expected\| (\S+) deg", text)
    assert len(ik) == 12 and all(ok == "True" and float(dq) < 1e-4 for ok, dq in ik), text
