"""A home pose free of self-contact for a fixed-base import (floating bases: stance.py).

The importer's first guess at `home` is 0 for every joint (the middle of the range where 0
is outside it). Many URDFs fold up at 0 (a 7-dof arm's wrist, a 6-dof arm's elbow, a hobby
arm's jaw, a mobile manipulator's arms inside its base), so the kit's servos would hold a
pose its own links penetrate. This module measures self-contact with MuJoCo on the links'
collision geometry (primitives, the convex hull of each given collision mesh, else the hull
of each visual piece; links joined by a joint, or by links without geometry, never collide,
as in the kit) and, where the guess is in contact, moves the joints between touching links
one at a time (small turns first, then a grid of the range) to the value that leaves the
least intrusion into `CLEARANCE`, until none is left or no move helps. The new pose is kept
when no two links touch in it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from simkit.importer.fixups.collide import (
    always_touching,
    between,
    collision_shapes,
    covered_shapes,
    model_xml,
    penetration,
    posed,
    touching,
    within_limits,
)
from simkit.importer.fixups.scratch import compiled

GRID = 8  # range divisions tried per joint
#: rad or m: turns (slides) from the first guess tried before the grid
STEPS = 0.05 * 2.0 ** np.arange(6)
SWEEPS = 3  # moves per joint at most


def free_home(robot, base_dir: Path, every: bool = False) -> tuple[list[float], list[str]] | None:
    """A home pose (spec order) with no self-contact and the changes made (`joint: a -> b`),
    or None when the spec's home is already free or the search finds no free pose. Only the
    joints between two links in contact move, each to the grid value that leaves the least
    penetration, the one nearest the first guess on a tie. A second search, from the first
    one's pose, adds the links' visual pieces (covered_shapes), which the kit's collision pieces
    are grown to cover (a humanoid hand's fingers, whose collision meshes sit apart from their
    visual ones, touch only there). `every`: pairs touching almost everywhere count too."""

    start, follow = posed(robot)
    if start is None:  # no movable joint: nothing to move
        return None
    q = start
    for shapes_of in (collision_shapes, covered_shapes):
        q = _search(robot, base_dir, q, follow, shapes_of, every)
    changes = [
        f"{j.name}: {start[i]:.4g} -> {q[i]:.4g}"
        for i, j in enumerate(robot.movable_joints)
        if abs(q[i] - start[i]) > 1e-12
    ]
    return ([float(f"{v:.6g}") for v in q], changes) if changes else None


def _search(robot, base_dir: Path, start, follow, shapes_of, every: bool = False) -> np.ndarray:
    """A pose free of contact on the model of `shapes_of`, from `start` (see free_home);
    `start` when it is free already or no free pose is found."""
    movable = robot.movable_joints
    index = {j.name: i for i, j in enumerate(movable)}
    always = () if every else always_touching(robot, base_dir, start, follow, shapes_of)
    model, data, adr = compiled(model_xml(robot, base_dir, always, shapes_of), movable)
    q = start.copy()
    best, pairs = penetration(model, data, adr, q)
    if not touching(data):  # closer than the clearance is fine at the first guess
        return start
    for _ in range(SWEEPS * len(movable)):
        joints = {j.name: j for a, b in sorted(pairs) for j in between(robot, a, b)}
        moved = False
        for j in joints.values():
            lo, hi = (j.lower, j.upper) if j.lower is not None else (-math.pi, math.pi)
            i = index[j.name]
            grid = np.concatenate(  # small turns first, then the range; never at a limit
                [start[i] + STEPS, start[i] - STEPS, np.linspace(lo, hi, GRID + 1)[1:-1]]
            )
            grid = grid[(grid > lo + 1e-6) & (grid < hi - 1e-6)]
            for value in sorted(grid, key=lambda v: abs(v - start[i])):
                trial = follow(np.where(np.arange(len(q)) == i, value, q))
                if not within_limits(movable, trial):  # a mimic follower left its range
                    continue
                depth, found = penetration(model, data, adr, trial)
                if depth < best - 1e-9:
                    q, best, pairs, moved = trial, depth, found, True
            if moved:
                break
        if best == 0.0 or not moved:
            break
    penetration(model, data, adr, q)
    return start if touching(data) else q  # no free pose found: the first guess stays


def in_contact(robot, base_dir: Path) -> bool:
    """Whether two links that the kit lets collide touch at the spec's home (the first
    search's model: collision shapes, the always-touching pairs left out)."""
    start, follow = posed(robot)
    if start is None:
        return False
    always = always_touching(robot, base_dir, start, follow, collision_shapes)
    xml = model_xml(robot, base_dir, always, collision_shapes)
    model, data, adr = compiled(xml, robot.movable_joints)
    penetration(model, data, adr, start)
    return touching(data)
