"""Alike joints of a legged robot's limbs, moved together by the stance search (stance.py).

At one quadruped's all-zero home each thigh sat 3.5 cm inside the trunk's collision hull.
Every joint carries a foot, so moving one hip alone lifts that foot off the floor and the
robot no longer rests on all of them; spreading all four hips by the same angle keeps the
stance symmetric and the feet level. Alike joints: movable, not mimic, as many joints from
the base, of the same type and with the same limits (a quadruped's four hip abduction
joints). A limb on the -y side whose URDF frames do not mirror its joint (the same axis on
both sides) turns the other way: both the same value and the value mirrored by side are
tried.
"""

from __future__ import annotations

import numpy as np

GRID = 24  # values per group tried over its range (not at a limit)


def groups(robot, poses: dict) -> list[tuple[list, np.ndarray]]:
    """Groups of two or more alike joints, each with the sign per joint that mirrors a -y
    side joint (the y of its origin in the base frame at home, `poses` from forward())."""
    parent = {j.child: j for j in robot.joints}
    base = robot.floating_joint.child if robot.floating_joint else robot.root
    inverse = np.linalg.inv(poses[base])

    def depth(joint) -> int:
        count, link = 0, joint.parent
        while link in parent:
            count += parent[link].movable
            link = parent[link].parent
        return count

    found: dict[tuple, list] = {}
    for joint in robot.movable_joints:
        if joint.mimic is None and joint.lower is not None:
            key = (depth(joint), joint.type, joint.lower, joint.upper)
            found.setdefault(key, []).append(joint)
    out = []
    for key in sorted(found, key=str):
        members = found[key]
        if len(members) >= 2:
            y = [float((inverse @ poses[j.child])[1, 3]) for j in members]
            out.append((members, np.array([-1.0 if v < 0 else 1.0 for v in y])))
    return out


def group_search(q: np.ndarray, depth, robot, poses: dict, index: dict, follow) -> np.ndarray:
    """The pose with the least `depth` (m of self-penetration), nearest `q` among equal ones,
    with one group of alike joints set to one value (or that value mirrored by side) over
    a GRID of their range; `q` where no group does better."""
    best, chosen = depth(q), q
    for members, side in groups(robot, poses):
        lo, hi = members[0].lower, members[0].upper
        idx = [index[j.name] for j in members]
        grid = np.linspace(lo, hi, GRID + 2)[1:-1]
        for value in sorted(grid, key=lambda v: (abs(v - float(np.mean(q[idx]))), v)):
            for signs in (np.ones(len(idx)), side):
                values = value * signs
                if np.any(values < lo) or np.any(values > hi):
                    continue
                trial = q.copy()
                trial[idx] = values
                trial = follow(trial)
                got = depth(trial)
                if got < best - 1e-9:
                    best, chosen = got, trial
            if best <= 0.0:
                return chosen
    return chosen
