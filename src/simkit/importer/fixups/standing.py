"""Where a floating-base robot stands: the height of its base above the floor at `home`.

A URDF says nothing about it (the free joint is implicit), but simkit's floating joint has an
origin that the legged checks drop the robot from. The importer puts the base so that the
lowest point of the collision geometry (the visual solid where a link collides with it) at
the home pose touches the floor (z = 0); it is recorded as an estimate.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np

from simkit.kitio.stl import from_stl
from simkit.model.kinematics import forward, rpy_matrix


def points(shape, base_dir: Path) -> np.ndarray:
    """Points bounding one primitive in its link frame (m): mesh vertices, box corners, or the
    corners of a round shape's bounding box."""
    if shape.kind == "mesh":
        local = from_stl((base_dir / shape.file).read_bytes()).vertices * shape.scale
    else:
        if shape.kind == "box":
            half = np.asarray(shape.size) / 2
        elif shape.kind == "sphere":
            half = np.full(3, shape.radius)
        else:  # cylinder, capsule, cone: along local z
            extra = shape.radius if shape.kind == "capsule" else 0.0
            half = np.array([shape.radius, shape.radius, shape.length / 2 + extra])
        local = np.array(list(itertools.product(*[(-h, h) for h in half])))
    return local @ rpy_matrix(shape.rpy).T + np.asarray(shape.xyz)


def lowest(shape, pose: np.ndarray, base_dir: Path) -> float:
    """World z (m) of a shape's lowest point with its link at `pose`: exact for round shapes
    (a tilted shin cylinder's bounding-box corners reach below the cylinder: a quadruped with its
    hips spread stood 1.7 cm above the floor), the lowest vertex or corner otherwise."""
    if shape.kind not in ("sphere", "cylinder", "capsule"):
        world = points(shape, base_dir) @ pose[:3, :3].T + pose[:3, 3]
        return float(world[:, 2].min())
    rotation = pose[:3, :3] @ rpy_matrix(shape.rpy)
    centre = pose[:3, :3] @ np.asarray(shape.xyz) + pose[:3, 3]
    if shape.kind == "sphere":
        return float(centre[2] - shape.radius)
    axis = rotation[:, 2]
    end = float(centre[2] - abs(axis[2]) * shape.length / 2)
    if shape.kind == "capsule":
        return end - shape.radius
    return end - shape.radius * float(np.sqrt(max(0.0, 1.0 - axis[2] ** 2)))


def floor_shapes(link) -> tuple:
    """What of a link can touch the floor in the kit: its collision primitives or given
    collision shapes where the spec has them (a quadruped's shin is a 2 cm cylinder inside a wider
    visual mesh), else its visual solid (whose hull or pieces the kit collides)."""
    if link.collision_method == "primitives":
        return link.collision_primitives
    if link.collision_method == "given" and link.collision_shapes:
        return link.collision_shapes
    return link.shapes


def standing_height(robot, base_dir: Path) -> float | None:
    """Height (m) of the floating base's origin that puts the robot's lowest point at home on
    the floor; None when no link has a solid."""
    home = dict(robot.poses).get("home")
    poses = forward(robot, home)
    lowest_z = None
    touching = any(floor_shapes(link) for link in robot.links)
    for link in robot.links:
        for shape in floor_shapes(link) if touching else link.shapes:
            z = lowest(shape, poses[link.name], base_dir)
            lowest_z = z if lowest_z is None else min(lowest_z, z)
    return None if lowest_z is None else -lowest_z
