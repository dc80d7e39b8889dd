"""A kit without a GPU scene says why in one line and still has every other file (issue 42,
class 9): where a robot cannot have a GPU scene (MuJoCo cannot compile its colliders, or no
solver setting holds its named poses within the `gpu_scene` check's tolerance), robot.json
`gpu_scene` carries `file: null` and the line, the README the same line, and neither the GPU
scene nor examples/mjx_demo.py is written; robot.json's `files` no longer lists it, so the
kit check does not look for it. The emitters run on the ECN 2R arm's model with that plan."""

from __future__ import annotations

from dataclasses import replace

from simkit.derive.gpu_budget import no_scene
from simkit.emit import docs, examples, mjcf_mjx, robot_json
from simkit.kitio import layout
from simkit.model.robot import SimReports
from simkit.pipeline import model_from_spec

REASON = "held at its named poses it ends 9.0 mm from where every contact puts it"


def test_a_kit_without_a_gpu_scene_says_why_in_one_line():
    robot = model_from_spec("ecn_2r")
    assert mjcf_mjx.emit(robot) and layout.example("mjx_demo.py") in examples.emit(robot)
    robot = replace(robot, products=replace(robot.products, gpu_scene=no_scene(REASON)))
    assert mjcf_mjx.emit(robot) == {}
    assert layout.example("mjx_demo.py") not in examples.emit(robot)
    doc = robot_json.document(robot, SimReports())
    assert doc["gpu_scene"] == {"file": None, "note": f"no GPU scene: {REASON}"}
    assert "mjcf_mjx" not in doc["files"]
    readme = docs.emit(robot)[layout.README].decode()
    assert f"no GPU scene: {REASON}." in readme and f"{robot.name}_mjx.xml" not in readme
