"""Estimated solids for a floating robot whose URDF has no geometry at all.

A masses-only humanoid URDF gives masses, CoMs and joints but neither `<visual>` nor
`<collision>`: the kit would have nothing to see and nothing to stand on, and it falls
through the floor. Each link with a URDF mass gets a box in its own axes that bounds its
origin, its child joints' origins and its CoM (so a limb spans from joint to joint and a foot
reaches its CoM), grown by the same thickness on every axis until it holds the link's mass
at DENSITY (water, a body's density), but by no more than MAX_SIDE. The box is the link's
solid and its collision primitive, marked `estimated` on the link; one report line for the
robot.
"""

from __future__ import annotations

import numpy as np

DENSITY = 1000.0  # kg/m^3 (importer/links.DENSITY: the zero-inertia sphere's)
MIN_SIDE = 0.01  # m: the thinnest a box gets, however light the link
#: m: the thickest: the URDF's joints sit closer than a heavy link's box would be wide (the
#: hips 9 cm off the waist, whose 6 kg box would be 15 cm thick), and estimated solids of
#: links that do not touch at home must not interpenetrate there
MAX_SIDE = 0.05


def _thickness(extent: np.ndarray, volume: float) -> float:
    """t (m) >= MIN_SIDE with prod(extent + t) = volume where the points leave room for it
    (bisection: the product rises with t)."""
    lo, hi = MIN_SIDE, max(MIN_SIDE, volume ** (1 / 3)) + MIN_SIDE
    if np.prod(extent + lo) >= volume:
        return lo
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if np.prod(extent + mid) < volume else (lo, mid)
    return min(hi, MAX_SIDE)


def estimated_box(mass: float, points: np.ndarray) -> dict:
    """The spec box (size, xyz, m, link frame) bounding `points` and holding `mass` kg at
    DENSITY."""
    low, high = points.min(axis=0), points.max(axis=0)
    extent = high - low
    size = extent + _thickness(extent, mass / DENSITY)
    centre = 0.5 * (low + high)
    box: dict = {"shape": "box", "size": [float(f"{s:.6g}") for s in size]}
    if np.any(centre):
        box["xyz"] = [float(f"{c:.6g}") for c in centre]
    return box


def add_solids(links: list[dict], joints: list[dict]) -> int:
    """Give each link with a URDF mass an estimated box (solid and collision); how many."""
    children: dict[str, list] = {}
    for joint in joints:
        children.setdefault(joint["parent"], []).append(joint.get("xyz", [0.0, 0.0, 0.0]))
    done = 0
    for link in links:
        if "mass" in link.get("estimated", []) or link.get("solid"):
            continue
        points = np.array([[0.0, 0.0, 0.0], link["com"], *children.get(link["name"], [])])
        box = estimated_box(float(link["mass"]), points)
        link["solid"] = [box]
        link["collision"] = "primitives"
        link["collision_primitives"] = [dict(box)]
        link["estimated"] = sorted({*link.get("estimated", []), "solid"})
        done += 1
    return done
