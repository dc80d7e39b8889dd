"""Derive steps: pure functions Robot -> Robot (solids, mass properties, servos, references)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from simkit import (
    collision_pairs,
    dynamics,
    freefall,
    inertia_decision,
    linkwork,
    massprops,
    motion,
)
from simkit.cache import Cache, derived_step
from simkit.emit import ros2_control
from simkit.errors import SpecError
from simkit.kinematics import forward
from simkit.model import Robot


def with_json(robot: Robot, key: str, value: object) -> Robot:
    """Return `robot` with a top-level robot.json entry added by a derive step (robot.json
    merges `derived["robot_json"]` after its own keys, in insertion order)."""
    extra = dict(robot.derived.get("robot_json", {}))
    extra[key] = value
    return replace(robot, derived={**robot.derived, "robot_json": extra})


def derive_solids(robot: Robot, base_dir: Path, cache: Cache | None = None) -> Robot:
    """Fill each link's visual solid from its primitives (through `cache`, if given)."""
    return linkwork.derive_solids(robot, base_dir, cache or Cache.disabled())


def derive_mass(robot: Robot) -> Robot:
    """CoM and inertia from the solid scaled to the link mass, unless the spec gives them."""
    links = []
    for link in robot.links:
        if link.inertial is None:
            try:
                link = replace(link, inertial=massprops.from_solid(link.solid, link.mass))
            except ValueError as exc:  # e.g. subtract removed the whole solid
                raise SpecError(link.name, None, "solid", f"link '{link.name}': {exc}") from None
        links.append(link)
    return replace(robot, links=tuple(links))


def _distance_from_axis(point: np.ndarray, origin: np.ndarray, axis: np.ndarray) -> float:
    r = point - origin
    return float(np.linalg.norm(r - axis * (axis @ r)))


def derive_references(robot: Robot) -> Robot:
    """FK reference poses (wrist centre, tool pose in the first link's frame) and reach."""
    movable = robot.movable_joints
    base = movable[0].parent if movable else robot.root
    tool = robot.tool_frame
    fk_reference = []
    for name, q in robot.poses:
        poses = forward(robot, q)
        inv = np.linalg.inv(poses[base])
        entry: dict = {"pose": name, "q": list(q)}
        if robot.wrist_centre:
            entry["wrist_centre"] = list((inv @ poses[robot.wrist_centre])[:3, 3])
        if tool:
            t = inv @ poses[tool]
            entry[tool] = {"xyz": list(t[:3, 3]), "rotation": t[:3, :3].tolist()}
        fk_reference.append(entry)
    derived = dict(robot.derived, fk_reference=fk_reference, base_frame=base)
    if "stretched" in dict(robot.poses) and movable and robot.wrist_centre and tool:
        poses = forward(robot, robot.pose("stretched"))
        first = poses[movable[0].child]
        origin, axis = first[:3, 3], first[:3, :3] @ np.asarray(movable[0].axis)
        derived["reach_geometric"] = {
            "wrist": _distance_from_axis(poses[robot.wrist_centre][:3, 3], origin, axis),
            "flange": _distance_from_axis(poses[tool][:3, 3], origin, axis),
        }
    return replace(robot, derived=derived)


def derive_all(
    robot: Robot,
    base_dir: Path,
    cache: Cache | None = None,
    jobs: int | None = None,
    progress: linkwork.Progress | None = None,
) -> Robot:
    """All derive steps in order. `cache` defaults to the user cache folder (`cache.py`);
    `jobs` is the process count for slow per-link steps (default: the cores)."""
    cache = Cache.at() if cache is None else cache
    robot = derive_solids(robot, base_dir, cache)
    robot = linkwork.derive_collision(robot, cache, jobs, progress)
    robot = derive_mass(robot)
    robot = inertia_decision.derive_inertia_decisions(robot)
    robot = dynamics.derive_actuators(robot)
    robot = derive_references(robot)
    robot = ros2_control.derive_ros2_control(robot)  # spec `ros2_control:` only
    # last: samples the final collision geometry
    robot = derived_step(robot, cache, "collision_pairs", collision_pairs.derive_collision_pairs)
    # motion data after the servos: its inverse-dynamics check reads the final MJCF
    robot = derived_step(robot, cache, "motion", motion.derive_motion)
    # free-fall validation (spec `freefall:`) last: it simulates the files the final model emits
    return derived_step(robot, cache, "freefall", freefall.derive_freefall)
