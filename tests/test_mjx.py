"""GPU scenes (`mjcf/NAME_mjx.xml`, issue 30), on the CPU: every seed kit's scene puts and
steps in MJX (JAX on the CPU) without NaN, within its stated contact slots, agreeing with C
MuJoCo; MuJoCo Warp steps it on Warp's CPU device; the kit check that it is the main MJCF's
robot fails on tampered copies. One subprocess runs scripts/bench_gpu.py --probe for all five
kits, so JAX's compilation happens once per kit and in a clean process."""

from __future__ import annotations

import importlib.util
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import SEED_ROBOTS
from simkit.check.gpu_scene import check_gpu_scene
from simkit.check.kit import Kit

REPO = Path(__file__).resolve().parents[1]
BENCH = REPO / "scripts" / "bench_gpu.py"
#: rad or m: MJX (float32) against C MuJoCo (float64) after 100 steps of 2 ms from the same
#: state; measured worst 6.2e-6 (Asimov standing on its feet), 4e-8 for the 2R arm
AGREEMENT = 1e-4

needs_mjx = pytest.mark.skipif(
    importlib.util.find_spec("mujoco.mjx") is None or importlib.util.find_spec("jax") is None,
    reason="mujoco-mjx and jax not installed (test extra)",
)


def _run(*args: str, timeout: int = 900) -> list[dict]:
    done = subprocess.run(
        [sys.executable, str(BENCH), *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return [json.loads(line) for line in done.stdout.splitlines() if line.startswith("{")]


@pytest.fixture(scope="module")
def probes(seed_kits) -> dict[str, dict]:
    kits = [str(seed_kits[name].kit_dir) for name in SEED_ROBOTS]
    return {row["kit"].removesuffix("_description"): row for row in _run("--probe", *kits)}


@needs_mjx
@pytest.mark.parametrize("name", SEED_ROBOTS)
def test_gpu_scene_steps_in_mjx(probes, name):
    row = probes[name]
    assert row["file"] == f"mjcf/{name}_mjx.xml"
    assert not row["nan"], row
    assert row["contact_slots"] <= row["budget"], row  # the slots robot.json states
    assert row["agreement"] <= AGREEMENT, row


@pytest.mark.skipif(importlib.util.find_spec("mujoco_warp") is None, reason="simkit[gpu]")
def test_gpu_scene_steps_in_mujoco_warp(seed_kits):
    """MuJoCo Warp, on Warp's CPU device where there is no GPU: the floating base standing on
    the floor, with the file's own nconmax and njmax."""
    (row,) = _run("--warp-probe", str(seed_kits["asimov"].kit_dir))
    assert not row["nan"] and 0 < row["nefc"] <= row["njmax"], row


def _copy(seed_kits, name: str, tmp_path: Path) -> Path:
    kit = tmp_path / f"{name}_description"
    shutil.copytree(seed_kits[name].kit_dir, kit)
    return kit


def _failures(kit: Path) -> list[str]:
    return [f.line() for f in check_gpu_scene(Kit.open(kit)) if not f.ok]


def test_the_seed_gpu_scenes_pass_the_check(seed_kits):
    for name in SEED_ROBOTS:
        findings = check_gpu_scene(Kit.open(seed_kits[name].kit_dir))
        assert len(findings) > 20 and all(f.ok for f in findings), name


@pytest.mark.parametrize(
    ("pattern", "replacement", "expected"),
    [
        (r'(<inertial [^>]*mass=")([0-9.]+)', r"\g<1>99", "body masses"),
        (r'(<joint name="J2" [^>]*axis=")[^"]*', r"\g<1>1 0 0", "joint axes"),
        (r'(<position name="J3" [^>]*kp=")[0-9.]+', r"\g<1>1", "servo gains"),
        (r'(name="link_4_collision_02" [^/]*contype=")0', r"\g<1>1", "outside explicit pairs"),
    ],
)
def test_a_tampered_gpu_scene_fails(seed_kits, tmp_path, pattern, replacement, expected):
    kit = _copy(seed_kits, "rosie_1000", tmp_path)
    path = kit / "mjcf" / "rosie_1000_mjx.xml"
    text = path.read_text()
    tampered, count = re.subn(pattern, replacement, text, count=1)
    assert count == 1
    path.write_text(tampered)
    failures = _failures(kit)
    assert failures and any(expected in line for line in failures), failures


def test_a_gpu_scene_that_stands_differently_fails(seed_kits, tmp_path):
    """Floor pairs dropped: the legged robot falls through the floor in the GPU scene."""
    kit = _copy(seed_kits, "asimov", tmp_path)
    path = kit / "mjcf" / "asimov_mjx.xml"
    path.write_text(re.sub(r'<pair geom1="floor"[^>]*/>', "", path.read_text()))
    doc = json.loads((kit / "robot.json").read_text())
    doc["gpu_scene"]["pairs"] -= len(doc["gpu_scene"]["floor_pairs"])
    (kit / "robot.json").write_text(json.dumps(doc))
    failures = _failures(kit)
    assert any("end where the main MJCF's do" in line for line in failures), failures


def test_a_broad_phase_that_drops_touching_pairs_fails(seed_kits, tmp_path):
    """max_geom_pairs 1 in the file and robot.json alike: the check's own seeded draw finds a
    configuration that touches through a pair MJX would then never narrow-phase."""
    kit = _copy(seed_kits, "rosie_1000", tmp_path)
    path = kit / "mjcf" / "rosie_1000_mjx.xml"
    text, count = re.subn(r'(name="max_geom_pairs" data=")\d+', r"\g<1>1", path.read_text())
    assert count == 1
    path.write_text(text)
    doc = json.loads((kit / "robot.json").read_text())
    doc["gpu_scene"]["max_geom_pairs"] = 1
    (kit / "robot.json").write_text(json.dumps(doc))
    failures = _failures(kit)
    assert any("broad phase keeps the pairs in contact" in line for line in failures), failures


@needs_mjx
@pytest.mark.xdist_group("mjx_demo")
def test_the_kit_mjx_demo_runs(ecn_2r_mjx_demo):
    """examples/mjx_demo.py, the document's snippet made runnable, with the batch size as an
    argument (`--batch 3 --steps 5`): it steps the batch and reports no NaN."""
    done = ecn_2r_mjx_demo
    assert done.returncode == 0, done.stderr[-2000:]
    assert "worlds: 3, steps: 5" in done.stdout and "any NaN: False" in done.stdout, done.stdout


def test_the_seed_builds_print_no_warning(seed_kits):
    """Every seed spec states its licence and that no source names a maintainer."""
    assert {name: seed_kits[name].warnings for name in SEED_ROBOTS} == dict.fromkeys(
        SEED_ROBOTS, ()
    )
