"""Which way up a URDF's COLLADA meshes are: as stored, or turned by their `<up_axis>`.

COLLADA says a file whose `<up_axis>` is Y_UP has +Y up, so a Z-up world turns it +90 deg
about x. ROS tools (RViz, MoveIt, Assimp-based loaders) ignore the tag, and most URDFs are
drawn for them (aerial manipulators, a two-dof arm: their Y_UP meshes fit as stored). Some
were drawn for a loader that honours it: one humanoid's meshes as stored lie across its links (the
shank along -z while the ankle joint sits 0.213 m along -x, where the turned shank ends),
so its limbs interpenetrate and it cannot stand. The URDF's own numbers decide, for the
whole file: the meshes are turned when that puts more child joint origins inside their
link's mesh bounds and brings the mesh centroids nearer the inertial CoMs. Reported.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simkit.importer.read.model import Link
from simkit.importer.read.source import Source, resolve_uri
from simkit.importer.translate.meshes import Y_UP_TO_Z_UP, is_y_up
from simkit.model.kinematics import rpy_matrix

SLACK = 0.01  # m a child joint origin may lie outside its link's mesh bounds


def _vertices(path: Path, scale) -> np.ndarray | None:
    import trimesh

    try:
        mesh = trimesh.load(str(path), force="mesh", process=False)
    except Exception:  # unreadable: the mesh writer reports it
        return None
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=float)
    return vertices if len(vertices) else None


def _fit(
    source: Source, link: Link, kids: list[np.ndarray], turn: bool
) -> tuple[int, float] | None:
    """(child joint origins inside the link's Y_UP visual meshes' bounds, distance m of their
    centroid from the inertial CoM) with the meshes turned or not; None without such a mesh."""
    points = []
    for visual in link.visuals:
        mesh = visual.shape
        if mesh is None or mesh.kind != "mesh" or not mesh.filename:
            continue
        try:
            path = resolve_uri(source, mesh.at, mesh.filename)
        except Exception:  # a missing mesh: the import reports it
            continue
        if not is_y_up(path):
            continue
        vertices = _vertices(path, None)
        if vertices is None:
            continue
        if turn:
            vertices = vertices @ Y_UP_TO_Z_UP.T
        vertices = vertices * np.asarray(mesh.scale)
        xyz, rpy = visual.origin.xyz, visual.origin.rpy
        points.append(vertices @ rpy_matrix(rpy).T + np.asarray(xyz))
    if not points:
        return None
    every = np.vstack(points)
    low, high = every.min(axis=0) - SLACK, every.max(axis=0) + SLACK
    inside = sum(bool(np.all((k >= low) & (k <= high))) for k in kids)
    centre = np.asarray(link.inertial.origin.xyz if link.inertial else (0.0, 0.0, 0.0))
    return inside, float(np.linalg.norm(every.mean(axis=0) - centre))


def turn_y_up(source: Source) -> tuple[bool, str]:
    """Whether this source's Y_UP COLLADA meshes are to be turned Z-up, and why (a report
    line; empty when they stay as stored). Reads `source.robot`."""
    kids: dict[str, list[np.ndarray]] = {}
    for joint in source.robot.joints:
        if joint.parent is not None:
            kids.setdefault(joint.parent, []).append(np.asarray(joint.origin.xyz))
    fits = {False: [0, 0.0, 0], True: [0, 0.0, 0]}
    for link in source.robot.links:
        if link.inertial is None:
            continue
        for turn in (False, True):
            fit = _fit(source, link, kids.get(link.name, []), turn)
            if fit is not None:
                fits[turn][0] += fit[0]
                fits[turn][1] += fit[1]
                fits[turn][2] += 1
    (as_in, off_as, links), (turned_in, off_turned, _n) = fits[False], fits[True]
    if not links:
        return False, ""
    turn = turned_in > as_in and off_turned < off_as
    why = (
        f"COLLADA meshes of {links} links marked <up_axis>Y_UP</up_axis> turned Z-up (ROS "
        f"tools do not): so {turned_in} child joint origins lie inside their link's mesh "
        f"bounds (as stored {as_in}) and the mesh centroids lie {off_turned / links:.3f} m "
        f"from the inertial CoMs on average (as stored {off_as / links:.3f} m)"
    )
    return turn, why if turn else ""
