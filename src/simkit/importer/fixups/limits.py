"""Estimated position limits narrowed to the range a joint turns through without self-contact.

A URDF joint without position limits gets +-pi rad (+-0.1 m) from the importer, marked
estimated. A real joint without a stop still cannot turn a link through its neighbours: the
double pendulum's second link folds onto the base at -180 deg. The kit's self-collision check
(issue 12) holds estimated limits to be free of self-contact, as for the seed robots, so the
estimate must be the free range, not a turn.

Each such joint is swept from home towards each limit, the others at home (mimic followers
follow), in `STEP` steps on the import's collision model (collide.py: the links' collision
shapes, plus their visual pieces, which the kit's collision pieces are grown to cover); the
first sample where two links come closer than `collide.CLEARANCE` ends the range, and the limit is
set `BACK_OFF` steps short of it. Published (URDF) limits are never changed.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from simkit.importer.fixups import collide
from simkit.importer.fixups.scratch import compiled

STEP = {"revolute": math.radians(0.5), "prismatic": 0.001}  # rad, m
BACK_OFF = 2  # steps kept clear of the first contact (the check sweeps in 2 deg steps)
DIGITS = 4  # decimals of a narrowed limit, rounded towards home


def narrowed(robot, base_dir: Path) -> dict[str, tuple[float, float]]:
    """{joint: (lower, upper)} for each joint whose estimated limits were narrowed (rad or
    m), none when home itself is in contact (nothing to measure a free range from)."""
    start, follow = collide.posed(robot)
    if start is None:
        return {}
    always = collide.always_touching(robot, base_dir, start, follow)
    xml = collide.model_xml(robot, base_dir, always, shapes_of=collide.covered_shapes)
    movable = robot.movable_joints
    model, data, adr = compiled(xml, movable)
    near = _closest(model, data, adr, start)
    if any(d <= 0.0 for d in near.values()):
        return {}
    blocked = _blocked_against(model, data, adr, near)
    out = {}
    for i, joint in enumerate(movable):
        if joint.mimic is not None or not {"lower", "upper"} & set(joint.estimated):
            continue
        ends = [
            _free_end(blocked, start, i, follow, end, STEP[joint.type])
            for end in (joint.lower, joint.upper)
        ]
        if (ends[0], ends[1]) != (joint.lower, joint.upper) and ends[1] - ends[0] > 1e-6:
            out[joint.name] = (ends[0], ends[1])
    return out


def _closest(model, data, adr, q) -> dict[tuple[int, int], float]:
    """The smallest distance (m) per body pair closer than the search clearance at `q`."""
    collide.penetration(model, data, adr, q)
    out: dict[tuple[int, int], float] = {}
    for contact in data.contact[: data.ncon]:
        pair = tuple(sorted(int(model.geom_bodyid[g]) for g in contact.geom))
        out[pair] = min(out.get(pair, math.inf), float(contact.dist))
    return out


def _blocked_against(model, data, adr, near: dict):
    """A test of a pose: a pair comes closer than the clearance, or, for pairs already that
    close at home (home.py keeps them apart, not a clearance apart), closer than half their
    distance at home."""

    def blocked(q: np.ndarray) -> bool:
        for pair, dist in _closest(model, data, adr, q).items():
            if dist < min(collide.CLEARANCE, 0.5 * near.get(pair, math.inf)):
                return True
        return False

    return blocked


def _free_end(blocked, start, i: int, follow, end: float, step: float) -> float:
    """`end` when the sweep from home reaches it free, else the last free value `BACK_OFF`
    steps short of the first contact, rounded towards home; home when there is none."""
    span = end - start[i]
    count = math.ceil(abs(span) / step)
    for k in range(1, count + 1):
        q = start.copy()
        q[i] = start[i] + span * k / count
        if blocked(follow(q)):
            free = start[i] + span * max(0, k - 1 - BACK_OFF) / count
            scale = 10.0**DIGITS
            rounded = (math.floor if span > 0 else math.ceil)(free * scale) / scale
            return rounded if abs(rounded - start[i]) < abs(span) else start[i]
    return end
