"""Mass properties a URDF leaves out, estimated from the links' own solids.

A URDF without `<inertial>` elements would otherwise become a robot of 1 g links (a 7 g
industrial arm that the kit's servos fling about). A massless link with a visual solid gets
the mass of that solid at `draft.DENSITY` (1400 kg/m^3, the corpora's median link; `--density`
sets another): the volume of each
visual piece (the closed mesh the importer writes, or the convex hull it writes for an open
mesh; primitives exactly), its centre of mass and its inertia, summed about the link's CoM.
Which links: every link with a solid when the URDF gives no link a mass; otherwise those on a
movable joint (a massless link on a fixed joint is the author's frame or housing, merged
into its parent). Marked `estimated`, reported per link.

The estimated rotor inertia (armature) of each joint is a fix-up: fixups/rotors.py.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from simkit.kitio.stl import from_stl
from simkit.model.kinematics import rpy_matrix


def _box_inertia(size, mass: float) -> np.ndarray:
    a, b, c = (float(s) for s in size)
    return mass / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def _cylinder_inertia(radius: float, length: float, mass: float) -> np.ndarray:
    side = mass * (3 * radius * radius + length * length) / 12.0
    return np.diag([side, side, mass * radius * radius / 2.0])


def _piece(shape: dict, stage: Path) -> tuple[float, np.ndarray, np.ndarray, str] | None:
    """(volume m^3, centroid m, inertia at unit density about the centroid kg m^2, what) of
    one spec primitive in its own frame; None for a shape without volume."""
    kind = shape["shape"]
    if kind == "mesh":
        import trimesh

        mesh = from_stl((stage / shape["file"]).read_bytes())
        solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)
        what = "mesh"
        if not solid.is_watertight or solid.volume <= 0:
            solid, what = solid.convex_hull, "convex hull"
        if solid.volume <= 0:
            return None
        return float(solid.volume), np.asarray(solid.center_mass), solid.moment_inertia, what
    if kind == "box":
        volume = float(np.prod(shape["size"]))
        return volume, np.zeros(3), _box_inertia(shape["size"], volume), "box"
    if kind == "sphere":
        r = float(shape["radius"])
        volume = 4.0 / 3.0 * math.pi * r**3
        return volume, np.zeros(3), np.eye(3) * 0.4 * volume * r * r, "sphere"
    r, length = float(shape["radius"]), float(shape["length"])
    if kind == "cone":  # a frustum: its volume, the inertia of a cylinder of the mean radius
        top = float(shape.get("radius_top") or 0.0)
        volume = math.pi * length / 3.0 * (r * r + r * top + top * top)
        return volume, np.zeros(3), _cylinder_inertia((r + top) / 2, length, volume), kind
    volume = math.pi * r * r * length
    if kind == "capsule":  # the end spheres too; inertia of the bounding cylinder
        volume += 4.0 / 3.0 * math.pi * r**3
        return volume, np.zeros(3), _cylinder_inertia(r, length + 2 * r, volume), kind
    return volume, np.zeros(3), _cylinder_inertia(r, length, volume), kind


def solid_mass(shapes: list[dict], stage: Path, density: float):
    """(mass kg, com m, inertia about the com kg m^2 (3x3, link axes), volume m^3, what
    the volumes came from) of a link's solid at `density`; None when it has no volume."""
    pieces = []
    for shape in shapes:
        got = _piece(shape, stage)
        if got is None:
            continue
        volume, centroid, inertia, what = got
        rotation = rpy_matrix(shape.get("rpy", (0.0, 0.0, 0.0)))
        centre = rotation @ centroid + np.asarray(shape.get("xyz", (0.0, 0.0, 0.0)))
        pieces.append((volume, centre, rotation @ inertia @ rotation.T, what))
    volume = sum(p[0] for p in pieces)
    if volume <= 0:
        return None
    mass = density * volume
    com = sum(p[0] * p[1] for p in pieces) / volume
    tensor = np.zeros((3, 3))
    for v, centre, inertia, _what in pieces:
        d = centre - com
        tensor += density * (inertia + v * (d @ d * np.eye(3) - np.outer(d, d)))
    whats = ", ".join(sorted({p[3] for p in pieces}))
    return mass, com, tensor, volume, whats
