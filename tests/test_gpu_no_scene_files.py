"""robot.json as written (`robot_json.emit`, whose `files` block lists the formats the kit
holds) leaves out the GPU scene a kit does not have: the block was made again after
`document` had dropped it, so a kit without a GPU scene listed `mjcf/NAME_mjx.xml` and its
`gpu_scene` check failed to open it (a USD-imported hand whose colliders MuJoCo cannot
compile)."""

from __future__ import annotations

import json
from dataclasses import replace

from simkit.derive.gpu_budget import no_scene
from simkit.emit import robot_json
from simkit.kitio import layout
from simkit.model.robot import SimReports
from simkit.pipeline import model_from_spec


def test_written_files_leave_out_a_missing_gpu_scene():
    robot = model_from_spec("ecn_2r")
    listed = json.loads(robot_json.emit(robot, SimReports())[layout.ROBOT_JSON])["files"]
    assert listed["mjcf_mjx"] == layout.mjcf_mjx(robot.name)
    robot = replace(robot, products=replace(robot.products, gpu_scene=no_scene("a reason")))
    listed = json.loads(robot_json.emit(robot, SimReports())[layout.ROBOT_JSON])["files"]
    assert "mjcf_mjx" not in listed and listed["mjcf"] == layout.mjcf(robot.name)
