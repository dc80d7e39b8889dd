"""The GPU scene's solver settings, per robot (issue 41): the fewest iterations and line-search
iterations for which the servos hold every named pose as with every contact at MuJoCo's default
solver, found by simulation at derive time, stated in robot.json `gpu_scene.solver` and proved
by the `gpu_scene` check, which holds both written files and fails a tampered count."""

from __future__ import annotations

import json
import re
import shutil

import mujoco
import numpy as np
import pytest

from simkit.check.gpu_scene import check_gpu_scene, held_positions
from simkit.check.kit import Kit
from simkit.derive.gpu_solver import (
    CANDIDATES,
    HOLD_MARGIN,
    converged_iterations,
    hold_errors,
)
from simkit.pipeline import model_from_spec


def test_the_solver_is_the_cheapest_converged_candidate_that_holds():
    """Asimov standing needs 3 Newton iterations in some steps: fewer hold it in C MuJoCo
    (0.6 mm at 1 / 1) but leave MJX 13 mm from C MuJoCo after 100 steps, so 3 / 6."""
    robot = model_from_spec("asimov")
    plan = robot.products.gpu_scene
    least = converged_iterations(robot, plan)
    eligible = [c for c in CANDIDATES if c[0] >= least]
    index = eligible.index((plan["iterations"], plan["ls_iterations"]))
    errors = hold_errors(robot, plan, eligible[: index + 1])
    assert least > 1 and plan["iterations"] >= least
    assert all(error > HOLD_MARGIN for error in errors[:-1]), errors
    assert errors[-1] <= HOLD_MARGIN and errors[-1] == pytest.approx(plan["hold"], abs=1e-6)


@pytest.fixture(scope="module")
def asimov(kit_factory):
    return kit_factory("asimov").kit_dir


def test_robot_json_states_the_hold_the_files_show(asimov):
    """The derive's own model of the hold agrees with the written files, held in C MuJoCo."""
    doc = json.loads((asimov / "robot.json").read_text())
    solver = doc["gpu_scene"]["solver"]
    files = doc["files"]
    main = mujoco.MjModel.from_xml_path(str(asimov / files.get("mjcf_scene", files["mjcf"])))
    gpu = mujoco.MjModel.from_xml_path(str(asimov / files["mjcf_mjx"]))
    assert (gpu.opt.iterations, gpu.opt.ls_iterations) == (
        solver["iterations"],
        solver["ls_iterations"],
    )
    apart = np.linalg.norm(
        held_positions(main, gpu.key_qpos[0], gpu.key_ctrl[0])
        - held_positions(gpu, gpu.key_qpos[0], gpu.key_ctrl[0]),
        axis=1,
    ).max()
    assert apart == pytest.approx(solver["hold_error_m"], abs=1e-4)


def _tamper(kit, tmp_path, iterations: int, in_robot_json: bool) -> list[str]:
    copy = tmp_path / kit.name
    shutil.copytree(kit, copy)
    doc = json.loads((copy / "robot.json").read_text())
    path = copy / doc["files"]["mjcf_mjx"]
    text, count = re.subn(r' iterations="\d+"', f' iterations="{iterations}"', path.read_text())
    assert count == 1
    path.write_text(text)
    if in_robot_json:
        doc["gpu_scene"]["solver"]["iterations"] = iterations
        (copy / "robot.json").write_text(json.dumps(doc))
    return [f.line() for f in check_gpu_scene(Kit.open(copy)) if not f.ok]


def test_an_iteration_count_that_breaks_the_hold_fails(asimov, tmp_path):
    """No solver iterations (file and robot.json alike): the robot sinks through the floor."""
    failures = _tamper(asimov, tmp_path, 0, in_robot_json=True)
    assert any("end where the main MJCF's do" in line for line in failures), failures


def test_an_iteration_count_robot_json_does_not_state_fails(asimov, tmp_path):
    failures = _tamper(asimov, tmp_path, 7, in_robot_json=False)
    assert any("solver iterations as robot.json states" in line for line in failures), failures
