"""The emitter registry: one module per output format, each `emit(robot) -> {path: bytes}`.

Emitters do no I/O, read no clock and draw no random numbers.
"""

from __future__ import annotations

from collections.abc import Callable

from simkit.emit import (
    docs,
    examples,
    glb,
    meshes,
    mjcf,
    mjcf_scene,
    motion_files,
    robot_json,
    ros2,
    ros2_control,
    srdf,
    step,
    urdf,
    usd,
    validation,
)
from simkit.model import Robot

Emitter = Callable[[Robot], dict[str, bytes]]

EMITTERS: dict[str, Emitter] = {
    "meshes": meshes.emit,
    "urdf": urdf.emit,
    "mjcf": mjcf.emit,
    "mjcf_scene": mjcf_scene.emit,
    "robot_json": robot_json.emit,
    "docs": docs.emit,
    "srdf": srdf.emit,
    "ros2": ros2.emit,
    "examples": examples.emit,
    "usd": usd.emit,
    "motion_files": motion_files.emit,
    "glb": glb.emit,
    "ros2_control": ros2_control.emit,
    "validation": validation.emit,
    "step": step.emit,
}


def emit_all(robot: Robot, emitters: dict[str, Emitter] | None = None) -> dict[str, bytes]:
    """Run every emitter; two emitters writing the same path is a bug, so it raises."""
    files: dict[str, bytes] = {}
    owner: dict[str, str] = {}
    for name, emitter in (emitters or EMITTERS).items():
        for path, data in emitter(robot).items():
            if path in files:
                raise RuntimeError(f"emitters '{owner[path]}' and '{name}' both write {path}")
            files[path] = data
            owner[path] = name
    return dict(sorted(files.items()))
