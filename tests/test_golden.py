"""Golden copies of emitted text files for a small spec: a reviewer sees every change to an
emitter's output as a diff of tests/golden/. Refresh with `pytest --update-golden`."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from simkit.emit import docs, mjcf, mjcf_mjx, robot_json, ros2, ros2_control, sdf, srdf, urdf
from simkit.kitio.jsonout import dumps
from simkit.model.robot import SimReports
from simkit.pipeline import model_from_spec

GOLDEN = Path(__file__).resolve().parent / "golden" / "planar_2r"
SPEC = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"


def _robot_json(robot) -> dict[str, bytes]:
    """robot.json with the installed library versions masked (they differ between machines,
    and the provenance block records them on purpose)."""
    files = robot_json.emit(robot, SimReports())
    doc = json.loads(files["robot.json"])
    doc["provenance"]["libraries"] = {name: "<masked>" for name in doc["provenance"]["libraries"]}
    return {"robot.json": dumps(doc)}


EMITTERS = {
    "urdf": urdf.emit,
    "mjcf": mjcf.emit,
    "mjcf_mjx": mjcf_mjx.emit,
    "srdf": srdf.emit,
    "sdf": sdf.emit,
    "docs": docs.emit,
    "ros2": ros2.emit,
    "robot_json": _robot_json,
}


@pytest.fixture(scope="module")
def robot():
    return model_from_spec(str(SPEC))


def _match_golden(files: dict[str, bytes], folder: Path, request) -> None:
    """Each file equals its golden copy under `folder` (or rewrites it with --update-golden)."""
    for rel, data in sorted(files.items()):
        golden = folder / rel
        if request.config.getoption("--update-golden"):
            golden.parent.mkdir(parents=True, exist_ok=True)
            golden.write_bytes(data)
            continue
        assert golden.is_file(), f"no golden copy of {rel}: run pytest --update-golden"
        assert data.decode("utf-8") == golden.read_text(encoding="utf-8"), rel


@pytest.mark.parametrize("emitter", sorted(EMITTERS))
def test_emitted_text_matches_golden(robot, emitter, request):
    files = EMITTERS[emitter](robot)
    assert files, emitter
    _match_golden(files, GOLDEN, request)


@pytest.fixture(scope="module")
def ecn_2r():
    return model_from_spec("ecn_2r")


def test_ros2_control_files_match_golden(ecn_2r, request):
    """controllers.yaml and gazebo.launch.py of the one seed robot with `ros2_control:`."""
    files = ros2_control.emit(ecn_2r)
    assert set(files) == {"config/controllers.yaml", "launch/gazebo.launch.py"}
    _match_golden(files, GOLDEN.parent / "ecn_2r", request)
