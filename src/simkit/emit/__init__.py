"""The emitter registry: one module per output format, each `emit(robot) -> {path: bytes}`.

Emitters do no I/O, read no clock and draw no random numbers.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from functools import partial

from simkit.emit import (
    docs,
    examples,
    freefall_files,
    glb,
    meshes,
    mjcf,
    mjcf_mjx,
    mjcf_scene,
    motion_files,
    robot_json,
    ros2,
    ros2_control,
    sdf,
    srdf,
    step,
    training,
    urdf,
    usd,
)
from simkit.kitio.forked import run_all
from simkit.model.robot import Robot, SimReports

Emitter = Callable[[Robot], dict[str, bytes]]

EMITTERS: dict[str, Emitter] = {
    "meshes": meshes.emit,
    "urdf": urdf.emit,
    "mjcf": mjcf.emit,
    "mjcf_scene": mjcf_scene.emit,
    "mjcf_mjx": mjcf_mjx.emit,
    "docs": docs.emit,
    "srdf": srdf.emit,
    "ros2": ros2.emit,
    "examples": examples.emit,
    "usd": usd.emit,
    "motion_files": motion_files.emit,
    "glb": glb.emit,
    "ros2_control": ros2_control.emit,
    "step": step.emit,
    "sdf": sdf.emit,
    "training": training.emit,
}


#: Emitters run in a forked child beside the others (kitio/forked.py): the STEP emitter's
#: Open CASCADE import and B-rep solids are most of a cold STEP kit's extra time.
BACKGROUND = ("step",)


def emit_all(robot: Robot, emitters: dict[str, Emitter] | None = None) -> dict[str, bytes]:
    """Run every model emitter (before the simulate stage)."""
    emitters = emitters or EMITTERS
    jobs = {name: partial(emitter, robot) for name, emitter in emitters.items()}
    return _collect(run_all(jobs, BACKGROUND))


def emit_reports(
    robot: Robot, reports: SimReports, step: bool = True, kit_files: Iterable[str] = ()
) -> dict[str, bytes]:
    """The report emitters, robot.json and the free-fall files, after the simulate stage, on
    its reports; `step`: whether the kit has a STEP assembly (robot.json `geometry.step`);
    `kit_files`: the model emitters' paths (robot.json `files` lists their formats)."""
    return _collect(
        {
            "robot_json": robot_json.emit(robot, reports, step=step, kit_files=kit_files),
            "freefall_files": freefall_files.emit(robot, reports),
        }
    )


def _collect(outputs: dict[str, dict[str, bytes]]) -> dict[str, bytes]:
    """Merge emitter outputs, sorted by path; two emitters writing one path is a bug."""
    files: dict[str, bytes] = {}
    owner: dict[str, str] = {}
    for name, produced in outputs.items():
        for path, data in produced.items():
            if path in files:
                raise RuntimeError(f"emitters '{owner[path]}' and '{name}' both write {path}")
            files[path] = data
            owner[path] = name
    return dict(sorted(files.items()))
