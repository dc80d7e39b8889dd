"""The derive stage: pure `Robot -> Robot` steps (`dataclasses.replace`), in the order
`derive_all` runs them. No step writes files, calls an emitter or runs a check; each returns a
new model whose links, joints or `products` hold what it computed."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import fields, replace
from pathlib import Path

from simkit.derive import (
    arm,
    collision_pairs,
    gpu_scene,
    mass,
    per_link,
    references,
    ros2_control,
    step_plan,
)
from simkit.kitio.cache import Cache, cached_stage, decode_plain, digest, encode_plain
from simkit.model import dynamics
from simkit.model.robot import Products, Robot

Step = Callable[[Robot], Robot]


def derive_all(
    robot: Robot,
    base_dir: Path,
    cache: Cache | None = None,
    jobs: int | None = None,
    progress: per_link.Progress | None = None,
) -> Robot:
    """All derive steps in order. `base_dir`: folder mesh files are relative to; `cache`
    defaults to the user cache folder; `jobs`: processes for the slow per-link steps."""
    cache = Cache.at() if cache is None else cache
    robot = per_link.derive_solids(robot, base_dir, cache)
    robot = per_link.derive_collision(robot, cache, jobs, progress)
    robot = mass.derive_mass(robot)
    robot = mass.derive_inertia_decisions(robot)
    robot = dynamics.derive_actuators(robot)
    robot = references.derive_references(robot)
    robot = ros2_control.derive_ros2_control(robot)  # spec `ros2_control:` only
    # last: both sample the final collision geometry, masses and servos
    robot = products_step(robot, cache, "collision_pairs", collision_pairs.derive_collision_pairs)
    robot = products_step(robot, cache, "gpu_scene", gpu_scene.derive_gpu_scene)
    robot = products_step(robot, cache, "step_plans", step_plan.derive_step_plans)
    return products_step(robot, cache, "motion", arm.derive_motion)


def products_step(robot: Robot, cache: Cache, name: str, step: Step) -> Robot:
    """Run a step that only adds `products` through the cache, keyed on the whole input model.
    On a hit the stored products fields are put back; a step that changed anything else, or
    products JSON cannot hold exactly, is simply not stored."""

    def run() -> dict:
        out = step(robot)
        if replace(out, products=robot.products) != robot:
            return {"_robot": out}  # changed more than products: never stored
        return {
            f.name: getattr(out.products, f.name)
            for f in fields(Products)
            if getattr(out.products, f.name) is not getattr(robot.products, f.name)
        }

    changed = cached_stage(
        cache,
        f"derived_{name}",
        [digest(robot).encode()],
        run,
        lambda value: None if "_robot" in value else encode_plain(value),
        lambda arrays: decode_plain(arrays),  # type: ignore[return-value]
        libraries=("numpy", "mujoco", "manifold3d"),
    )
    if "_robot" in changed:
        return changed["_robot"]
    return replace(robot, products=replace(robot.products, **changed))
