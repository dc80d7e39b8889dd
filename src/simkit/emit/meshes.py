"""Mesh emitter: one visual STL per link and the convex collision pieces as OBJ, link frame,
metres."""

from __future__ import annotations

from simkit.kitio import layout
from simkit.kitio.obj import to_obj
from simkit.kitio.stl import to_stl
from simkit.model.robot import Robot


def emit(robot: Robot) -> dict[str, bytes]:
    """`meshes/visual/LINK.stl` and `meshes/collision/LINK_NN.obj`."""
    out: dict[str, bytes] = {}
    for link in robot.links:
        if link.solid is not None:
            out[layout.visual_mesh(link.name)] = to_stl(link.solid, link.name)
        for i, piece in enumerate(link.collision):
            out[layout.collision_mesh(link.name, i)] = to_obj(piece, f"{link.name}_{i:02d}")
    return out
