"""`training.present`: robot.json alone says whether a kit must carry `training/` (a GPU scene
file and servos with finite efforts), so a kit whose training/ was deleted fails the check, a
kit that never had one passes with the reason, and training/ in a kit without a GPU scene fails.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from simkit.check.kit import Kit
from simkit.check.training import check_training, expected_training

pytestmark = pytest.mark.slow


def _present(kit_dir: Path):
    return next(f for f in check_training(Kit.open(kit_dir)) if f.check == "training.present")


def _copy(kit_factory, tmp_path: Path) -> Path:
    copy = tmp_path / "kit"
    shutil.copytree(kit_factory("ecn_2r").kit_dir, copy)
    return copy


def _without_gpu_scene(kit_dir: Path) -> None:
    path = kit_dir / "robot.json"
    doc = json.loads(path.read_text(encoding="utf-8"))
    doc["gpu_scene"] = {"file": None, "note": "no GPU scene: a made-up reason"}
    path.write_text(json.dumps(doc), encoding="utf-8")


def test_seed_kit_must_have_training(kit_factory):
    assert expected_training(Kit.open(kit_factory("ecn_2r").kit_dir).doc) is None


def test_deleted_training_fails(kit_factory, tmp_path):
    kit = _copy(kit_factory, tmp_path)
    shutil.rmtree(kit / "training")
    assert not _present(kit).ok


def test_no_gpu_scene_and_no_training_passes_with_reason(kit_factory, tmp_path):
    kit = _copy(kit_factory, tmp_path)
    shutil.rmtree(kit / "training")
    _without_gpu_scene(kit)
    found = _present(kit)
    assert found.ok and "no GPU scene to train on" in found.line()


def test_training_without_gpu_scene_fails(kit_factory, tmp_path):
    kit = _copy(kit_factory, tmp_path)
    _without_gpu_scene(kit)
    assert not _present(kit).ok


def test_unlimited_servo_means_no_training():
    doc = {"gpu_scene": {"file": "mjcf/x_mjx.xml"}, "actuators": [{"forcerange": "Infinity"}]}
    assert expected_training(doc) == "a servo without an effort limit"
    assert expected_training({**doc, "actuators": [{"forcerange": None}]}) == expected_training(doc)
    assert expected_training({**doc, "actuators": []}).startswith("no position servos")
