"""The optional `loops:` section of a spec: kinematic loops closed by a constraint.

A kit's joints form a tree. A mechanism whose links meet twice (an end effector fixed both
to the arm and to the world, a four-bar) keeps its tree and closes each loop here: link
`link2` is held at `xyz`/`rpy` (m, rad; or `rpy_deg`) in `link1`'s frame, the pose it has at
`home`. `type: weld` holds all six degrees of freedom (MuJoCo `<equality><weld>`, a USD
FixedJoint excluded from the articulation); the field leaves room for `connect` (a ball
closure, position only) to follow.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterator
from typing import Literal

import numpy as np

from simkit.spec.names import name_problem
from simkit.spec.placed import Placed

Problem = tuple[tuple, str]

#: closure types a spec may name: a weld holds position and orientation
TYPES = ("weld",)
#: m and rad: how far a named pose may put link2 from its loop pose (the spec's own rounding)
POSE_TOL = 1e-6


class LoopSpec(Placed):
    """One loop closure: `link2`'s frame held at `xyz`/`rpy` in `link1`'s frame (its pose at
    the spec's home). `link1` may be the root frame (the world)."""

    name: str
    type: Literal["weld"] = "weld"
    link1: str
    link2: str


def _unknown(name: str, known: set[str]) -> str:
    """`unknown link 'X'`, with the closest known name when one is close."""
    close = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.6)
    return f"unknown link '{name}'" + (f"; did you mean '{close[0]}'?" if close else "")


def problems(spec) -> Iterator[Problem]:
    """Each loop names two different known links (or the root) not joined directly by a
    joint (a joint holds them already), a name no joint or other loop has, and each pair
    once."""
    known = {link.name for link in spec.links} | {spec.root}
    jointed = {frozenset((j.parent, j.child)) for j in spec.joints}
    names = {j.name for j in spec.joints}
    pairs: set[frozenset] = set()
    for i, loop in enumerate(spec.loops):
        why = name_problem(loop.name)
        if why:
            yield ("loops", i, "name"), why
        elif loop.name in names:
            yield ("loops", i, "name"), f"name '{loop.name}' is already used by a joint or loop"
        names.add(loop.name)
        bad = [(f, n) for f, n in (("link1", loop.link1), ("link2", loop.link2)) if n not in known]
        for field, name in bad:
            yield ("loops", i, field), _unknown(name, known)
        pair = frozenset((loop.link1, loop.link2))
        if bad:
            continue
        floating = spec.floating_base or any(j.type == "floating" for j in spec.joints)
        if loop.link1 == loop.link2:
            yield ("loops", i, "link2"), f"a loop joins two links, not '{loop.link1}' to itself"
        elif floating and spec.root in pair:
            why = f"a floating base moves freely: no loop closes on the root '{spec.root}'"
            yield ("loops", i, "link1" if loop.link1 == spec.root else "link2"), why
        elif pair in jointed:
            why = f"'{loop.link1}' and '{loop.link2}' are joined by a joint: no loop to close"
            yield ("loops", i, "link2"), why
        elif pair in pairs:
            yield ("loops", i, "link2"), f"'{loop.link1}' and '{loop.link2}' are closed twice"
        pairs.add(pair)


def _rot(rpy) -> np.ndarray:
    """R = Rz(yaw) Ry(pitch) Rx(roll), URDF's convention (model/kinematics.rpy_matrix)."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _placed(xyz, rot) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rot, xyz
    return out


def _forward(joints, root: str, values: dict[str, float]) -> dict[str, np.ndarray]:
    """T_root_link of every link at joint `values` (rad or m; 0 where none), the joints in
    depth-first order."""
    poses = {root: np.eye(4)}
    for joint in joints:
        motion = np.eye(4)
        q = values.get(joint.name, 0.0)
        axis = np.asarray(joint.axis, dtype=float) / np.linalg.norm(joint.axis)
        if joint.type == "prismatic":
            motion[:3, 3] = axis * q
        elif joint.type in ("revolute", "continuous"):
            k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
            motion[:3, :3] = np.eye(3) + math.sin(q) * k + (1 - math.cos(q)) * k @ k
        origin = _placed(joint.xyz, _rot(joint.rpy_rad()))
        poses[joint.child] = poses[joint.parent] @ origin @ motion
    return poses


def pose_problems(spec, joints) -> Iterator[Problem]:
    """Every named pose (`home` at least: all joints at 0 without one) keeps each loop
    closed: the tree puts `link2` at the loop's pose in `link1`'s frame. `joints`: the
    spec's joints depth-first (the order pose values follow)."""
    if not spec.loops:
        return
    movable = [j.name for j in joints if j.movable]
    named = {name: list(values) for name, values in spec.poses.items()}
    named.update({n: [math.radians(v) for v in q] for n, q in spec.poses_deg.items()})
    named.setdefault("home", [0.0] * len(movable))
    for pose, values in named.items():
        poses = _forward(joints, spec.root, dict(zip(movable, values, strict=True)))
        for i, loop in enumerate(spec.loops):
            want = _placed(loop.xyz, _rot(loop.rpy_rad()))
            got = np.linalg.inv(poses[loop.link1]) @ poses[loop.link2]
            gap = float(np.linalg.norm(want[:3, 3] - got[:3, 3]))
            cos = (np.trace(want[:3, :3].T @ got[:3, :3]) - 1) / 2
            turn = float(np.arccos(np.clip(cos, -1.0, 1.0)))
            if max(gap, turn) > POSE_TOL:
                yield (
                    ("loops", i, "xyz"),
                    f"pose '{pose}' puts '{loop.link2}' {gap:.3g} m and {turn:.3g} rad from "
                    f"the loop's pose in '{loop.link1}''s frame (the loop must be closed in "
                    "every named pose)",
                )
