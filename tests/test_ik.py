"""Analytic IK of the wrist-partitioned 6R chain and the kit's ik_cases.json (kit page,
000_5f76ade803e16979.txt, "IK reference cases")."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from page_snippets import IK_CASES_SNIPPET
from simkit.check.kit import Kit
from simkit.derive import ik_cases
from simkit.model import ik
from simkit.pipeline import model_from_spec


@pytest.fixture(scope="module")
def arm():
    return ik.arm_chain(model_from_spec("rosie_1000"))


@pytest.fixture(scope="module")
def cases(rosie_1000) -> dict:
    return json.loads((rosie_1000.kit_dir / "ik_cases.json").read_text(encoding="utf-8"))


def _fk_ik_module(kit_dir):
    spec = importlib.util.spec_from_file_location("kit_fk_ik", kit_dir / "examples" / "fk_ik.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _target(case: dict) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3], T[:3, :3] = case["target"]["xyz"], case["target"]["rotation"]
    return T


ARMS = ["rosie_600", "rosie_1000", "rosie_1400"]


@pytest.mark.parametrize("name", ARMS)
def test_page_snippet_passes_on_the_emitted_file(kit_factory, name):
    done = subprocess.run(
        [sys.executable, "-c", IK_CASES_SNIPPET],
        cwd=kit_factory(name).kit_dir,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    match = re.fullmatch(r"(\d+) cases, worst error (\S+) tolerance (\S+)\n", done.stdout)
    assert match, done.stdout
    assert int(match.group(1)) == 12
    assert float(match.group(2)) < float(match.group(3)) <= 1e-6


@pytest.mark.parametrize("name", ARMS)
def test_every_solution_is_within_limits_and_reaches_the_target(kit_factory, name):
    kit = Kit.open(kit_factory(name).kit_dir)
    cases = json.loads(kit.path("ik_cases.json").read_text(encoding="utf-8"))
    lower = np.array([j["lower"] for j in kit.joints])
    upper = np.array([j["upper"] for j in kit.joints])
    total = 0
    for case in cases["cases"]:
        target = _target(case)
        sols = [case["expected"], *case["all_solutions"]]
        total += len(sols)
        for sol in sols:
            q = np.asarray(sol["q"])
            assert np.all(q >= lower) and np.all(q <= upper)
            assert ik.pose_error(kit.fk(q), target) < 1e-6  # robot.json FK, not the IK chain
            assert {sol["shoulder"], sol["elbow"], sol["wrist"]} <= {
                "front",
                "back",
                "up",
                "down",
                "noflip",
                "flip",
            }
        # the expected solution is the end of the resolved move, which starts at the seed
        move = np.asarray(case["move"]["q"])
        assert np.allclose(move[0], case["seed"]["q"]) and np.allclose(move[-1], sols[0]["q"])
        assert np.abs(np.diff(move, axis=0)).max() < ik_cases.MAX_STEP
    # +-2 pi multiples of J1, J4, J6 add solutions to the 8 branches; the elbow limits at the
    # collision-free range (issue 12: J3 up to +60..+70 deg) remove some of the elbow branches
    assert total > 12 * 6


def test_cases_spread_over_the_workspace(cases):
    q1 = [case["expected"]["q"][0] for case in cases["cases"]]
    assert np.ptp(q1) > np.radians(270)
    branches = {(c["expected"]["shoulder"], c["expected"]["elbow"]) for c in cases["cases"]}
    assert len(branches) >= 3


def test_analytic_solutions_agree_with_the_kit_dls_solver(rosie_1000, cases, arm):
    fk_ik = _fk_ik_module(rosie_1000.kit_dir)
    chain = fk_ik.Chain.from_kit(rosie_1000.kit_dir / "robot.json")
    for case in cases["cases"]:  # from the seed, DLS lands on the expected solution
        q, ok, dp, dr = chain.ik(_target(case), case["seed"]["q"])
        assert ok and dp < 1e-9 and dr < 1e-9
        assert np.abs(q - case["expected"]["q"]).max() < 1e-6
    rng = np.random.default_rng(5)
    found = 0
    for _ in range(20):  # from nearby starts, every DLS answer is one of the analytic ones
        q_true = rng.uniform(arm.lower, arm.upper)
        q, ok, _, _ = chain.ik(arm.fk(q_true), q_true + rng.normal(scale=0.2, size=6))
        if not ok:
            continue
        found += 1
        sols = ik.solve(arm, arm.fk(q))
        assert min(np.abs(np.subtract(s.q, q)).max() for s in sols) < 1e-6
    assert found >= 15


def test_solver_returns_the_generating_pose_for_general_offsets(arm):
    """Shoulder x-offset (as the Rosie 1400), lateral offsets and negative axes."""
    rng = np.random.default_rng(11)
    origins = arm.origins.copy()
    origins[1] += [0.175, 0.02, 0.0]
    origins[2] += [0.0, -0.03, 0.0]
    origins[3] += [0.0, 0.0, 0.035]
    signs = np.array([1.0, -1.0, 1.0, -1.0, 1.0, -1.0])
    other = dataclasses.replace(arm, origins=origins, axes=arm.axes * signs[:, None], signs=signs)
    for chain_ in (arm, other):
        for _ in range(100):
            q = rng.uniform(chain_.lower, chain_.upper)
            sols = ik.solve(chain_, chain_.fk(q))
            assert min(np.abs(np.subtract(s.q, q)).max() for s in sols) < 1e-7
            assert all(ik.pose_error(chain_.fk(s.q), chain_.fk(q)) < 1e-9 for s in sols)
            assert all(chain_.within_limits(s.q) for s in sols)


def test_branch_flags(arm):
    assert ik.branch_flags(arm, [0, 0, 0, 0, 0, 0]) == ("front", "up", "noflip")
    q = np.radians([10, 20, 30, 40, -50, 60])
    branches = ik.principal_solutions(arm, arm.fk(q), 0.0)  # the eight, before the joint limits
    assert len({(s.shoulder, s.elbow, s.wrist) for s in branches}) == 8
    assert all(ik.pose_error(arm.fk(s.q), arm.fk(q)) < 1e-9 for s in branches)
    assert ik.branch_flags(arm, q) == ("front", "up", "noflip")


def test_other_robots_have_no_arm_chain():
    robot = model_from_spec(str(Path(__file__).parent / "specs" / "planar_2r.yaml"))
    assert ik.arm_chain(robot) is None
