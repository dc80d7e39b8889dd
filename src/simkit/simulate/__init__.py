"""The simulate stage: MuJoCo runs on the staged (written) MJCF and URDF, returning plain
reports (`model.robot.SimReports`) that the report emitters turn into robot.json entries and
validation files. It reads files, never calls an emitter, and never imports the checks."""

from __future__ import annotations

from pathlib import Path

from simkit.model.robot import Robot, SimReports
from simkit.simulate import benchmark, freefall, self_collision


def simulate_all(kit_dir: Path, robot: Robot) -> SimReports:
    """Every simulation the spec asks for, on the kit written at `kit_dir`."""
    return SimReports(
        freefall=freefall.run(kit_dir, robot),
        benchmark_torques=benchmark.run(kit_dir, robot),
        self_collision=self_collision.run(kit_dir, robot),
    )
