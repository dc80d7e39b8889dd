"""A home pose free of self-contact for a floating-base import, feet left where they are.

The importer's first guess at `home` is 0 for every joint (mid-range where 0 is outside).
Humanoids often hang their arms through their thighs at 0 (one humanoid's grippers sat 7 cm
inside its thigh hulls), so the kit's servos would hold a pose its own links penetrate and the
robot pushes itself over. This module measures self-contact with MuJoCo on the links'
collision geometry as the spec gives it (primitives, the convex hull of each given collision
mesh, else of each visual piece) with the kit's exclusions (links joined by a joint or welded
by fixed joints), ignores pairs in contact in every sampled configuration (the kit excludes
those, derive/collision_pairs.always_pairs), and moves one joint at a time to the value on a
grid of its range that leaves the least penetration. Joints that carry a foot (a link whose
lowest point at home is on the floor) stay put: the stance is the standing check's business.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np

from simkit.importer.fixups.alike import group_search
from simkit.importer.fixups.collide import between
from simkit.importer.fixups.scratch import Scratch, compiled
from simkit.importer.fixups.standing import floor_shapes, points
from simkit.model.kinematics import forward

GRID = 8  # range divisions tried per joint
SWEEPS = 2
SAMPLES = 200  # random configurations that tell an always-touching pair
FOOT = 0.01  # m: a link whose lowest point is this close to the robot's lowest is a foot
SUPPORT = 0.003  # m: solid points this close to the lowest one touch the floor
MARGIN = 0.01  # m: how far inside its support the CoM of a robot at rest must lie
#: m: penetration the kit's self-collision check allows (simulate/self_collision.TOLERANCE)
TOUCH = 0.0005
STABLE_SAMPLES = 2000
PAIR_JOINTS = 3  # joints next to a stuck pair moved two at a time
PAIR_GRID = 24  # values per joint in that search  # random poses tried for one the robot rests on


def stance_shapes(link) -> tuple:
    return link.collision_primitives or link.collision_shapes or link.shapes


def model_xml(robot, base_dir: Path) -> str:
    """Collision geometry only (scratch.py); every body but a fixed joint's child moves
    (fixed children are welded, as MuJoCo does in the kit), the parent filter on, the pairs
    the source excludes (`contact_excludes`) excluded."""
    scratch = Scratch(compiler={"angle": "radian"}, geom={"contype": "1", "conaffinity": "1"})
    scratch.tree(robot, base_dir, stance_shapes)
    links = {link.name for link in robot.links}
    jointed = [(j.parent, j.child) for j in robot.joints if j.parent in links]
    scratch.exclude([*jointed, *robot.contact_excludes])
    return scratch.xml()


def contacts(model, data, adr, q) -> dict[tuple[str, str], float]:
    """Deepest penetration (m, > 0) per touching body pair at `q`."""
    import mujoco

    data.qpos[adr] = q
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    out: dict[tuple[str, str], float] = {}
    for contact in data.contact[: data.ncon]:
        a = model.body(model.geom_bodyid[contact.geom1]).name
        b = model.body(model.geom_bodyid[contact.geom2]).name
        pair = (a, b) if a < b else (b, a)
        out[pair] = max(out.get(pair, 0.0), -float(contact.dist))
    return out


def _feet_joints(robot, home, base_dir: Path) -> set[str]:
    """Joints on the way from the base to any link whose lowest point at home is a foot."""
    poses = forward(robot, home)
    low: dict[str, float] = {}
    for link in robot.links:
        for shape in floor_shapes(link):
            world = points(shape, base_dir) @ poses[link.name][:3, :3].T
            z = float((world[:, 2] + poses[link.name][2, 3]).min())
            low[link.name] = min(low.get(link.name, math.inf), z)
    if not low:
        return set()
    lowest = min(low.values())
    parent = {j.child: j for j in robot.joints}
    out: set[str] = set()
    for name, z in low.items():
        while z <= lowest + FOOT and name in parent:
            out.add(parent[name].name)
            name = parent[name].parent
    return out


def _chain(parent: dict, link: str) -> list:
    """The joints from the root down to `link`."""
    out = []
    while link in parent:
        out.append(parent[link])
        link = parent[link].parent
    return out


class Support:
    """Where the robot touches a flat floor at a pose, and how far inside that support its
    centre of mass lies (the geometry that touches the floor, as standing.py places it)."""

    def __init__(self, robot, base_dir: Path):
        self.robot = robot
        self.points = {
            link.name: np.vstack([points(shape, base_dir) for shape in floor_shapes(link)])
            for link in robot.links
            if floor_shapes(link)
        }
        parent = {j.child: j for j in robot.joints}
        self.frame = {  # links no movable joint separates from the floating base
            link.name
            for link in robot.links
            if all(j.type in ("fixed", "floating") for j in _chain(parent, link.name))
        }
        self.mass = {
            link.name: (link.inertial.mass, np.asarray(link.inertial.com))
            for link in robot.links
            if link.inertial is not None
        }

    def margin(self, q, frame_only: bool = False) -> float:
        """m the CoM's ground projection lies inside the convex hull of the lowest points
        (within SUPPORT of the lowest); negative outside, or for a point or a line of
        support (point feet side by side: it can only balance, never rest). `frame_only`:
        -inf unless every lowest point is on the base or links welded to it (no servo
        carries the weight)."""
        from scipy.spatial import ConvexHull, QhullError

        poses = forward(self.robot, list(q))
        world = [pts @ poses[n][:3, :3].T + poses[n][:3, 3] for n, pts in self.points.items()]
        if not world or not self.mass:
            return math.inf
        every = np.vstack(world)
        low = every[:, 2] <= every[:, 2].min() + SUPPORT
        owners = np.repeat(list(self.points), [len(p) for p in self.points.values()])
        if frame_only and not set(owners[low]) <= self.frame:
            return -math.inf
        feet = every[low][:, :2]
        total = sum(m for m, _ in self.mass.values())
        com = sum(m * (poses[n][:3, :3] @ c + poses[n][:3, 3]) for n, (m, c) in self.mass.items())
        com = np.asarray(com)[:2] / total
        try:
            hull = ConvexHull(feet)
        except (QhullError, ValueError):  # fewer than 3 points, or all on a line
            return -float(np.min(np.linalg.norm(feet - com, axis=1))) - MARGIN
        return float(np.min(-(hull.equations[:, :2] @ com + hull.equations[:, 2])))


def _follow(q: np.ndarray, movable, index: dict[str, int]) -> np.ndarray:
    """Rows of joint values with each mimic joint at its leader's (the kit's equality)."""
    for j in movable:
        if j.mimic is not None and j.mimic[0] in index:
            leader, multiplier, offset = j.mimic
            q[:, index[j.name]] = multiplier * q[:, index[leader]] + offset
    return q


def _resting(q, support: Support, depth, movable, limits, index) -> np.ndarray:
    """The seeded random pose nearest `q` (joint-space distance) on which the robot rests
    (CoM at least MARGIN inside its support) with no more self-contact than `q`, resting on
    its frame alone where a draw allows (a tilt-rotor's arm servos, 0.3 N m, cannot carry it);
    `q` itself when none of them does. Random draws, not one joint at a time: a flying arm must move
    two joints together to lift above its frame."""
    free = depth(q)
    lo, hi = np.array(limits, dtype=float).T
    draws = lo + np.random.default_rng(0).random((STABLE_SAMPLES, len(movable))) * (hi - lo)
    draws = _follow(draws, movable, index)
    ordered = draws[np.argsort(np.linalg.norm(draws - q, axis=1), kind="stable")]
    for frame_only in (True, False):  # on its frame if it can (a drone), else on its joints
        for trial in ordered:
            if support.margin(trial, frame_only) >= MARGIN and depth(trial) <= free + 1e-9:
                return trial
    return q


def better(got, best) -> bool:
    """A score (a number, or a tuple compared in order) higher than `best` by more than
    rounding."""
    got, best = np.atleast_1d(got), np.atleast_1d(best)
    for a, b in zip(got, best, strict=True):
        if abs(a - b) > 1e-9:
            return bool(a > b)
    return False


def _pair_search(q, depth, robot, model, data, adr, always, frozen, limits, index):
    """For each link pair still in contact, the joints between them (distal first, the
    first PAIR_JOINTS not frozen) two at a time over a PAIR_GRID x PAIR_GRID grid of their
    ranges: the pose with the least `depth`. A humanoid's shoulder may clear its chest only
    with pitch and roll moved together."""
    movable = robot.movable_joints
    best = depth(q)
    for pair in sorted(p for p in contacts(model, data, adr, q) if p not in always):
        joints = [j for j in between(robot, *pair) if j.name not in frozen][:PAIR_JOINTS]
        for a, b in itertools.combinations(joints, 2):
            ia, ib = index[a.name], index[b.name]
            grid_a = np.linspace(*limits[ia], PAIR_GRID + 2)[1:-1]
            grid_b = np.linspace(*limits[ib], PAIR_GRID + 2)[1:-1]
            for va, vb in itertools.product(grid_a, grid_b):
                trial = q.copy()
                trial[ia], trial[ib] = va, vb
                trial = _follow(trial[None, :], movable, index)[0]
                got = depth(trial)
                if got < best - 1e-9:
                    q, best = trial, got
            if best <= 0.0:
                return q
    return q


def _alike(q, depth, robot, index, movable) -> np.ndarray:
    """alike.group_search from `q`, mimic joints following."""
    poses = forward(robot, list(q))
    return group_search(
        q, depth, robot, poses, index, lambda t: _follow(t[None, :], movable, index)[0]
    )


def free_home(robot, base_dir: Path, rest: bool = True) -> tuple[list[float], list[str]] | None:
    """A home pose (spec order) whose separable link pairs do not touch and on which the
    robot rests on the floor (its CoM at least MARGIN inside its support), and the changes
    made (`joint: a -> b`); None when home already is, or no grid pose is better. `rest`
    False: no floor (a legged robot bolted at its base): free of contact, legs kept."""
    home = dict(robot.poses).get("home")
    if home is None:
        return None
    movable = robot.movable_joints
    model, data, adr = compiled(model_xml(robot, base_dir), movable)
    limits = [(j.lower, j.upper) if j.lower is not None else (-math.pi, math.pi) for j in movable]
    index = {j.name: i for i, j in enumerate(movable)}
    lo, hi = np.array(limits, dtype=float).T
    draws = lo + np.random.default_rng(0).random((SAMPLES, len(movable))) * (hi - lo)
    draws = _follow(draws, movable, index)
    always: set | None = None
    for q in draws:
        touching = set(contacts(model, data, adr, q))
        always = touching if always is None else always & touching
    always = always or set()

    def depth(q) -> float:
        """m of penetration beyond TOUCH, summed over the separable pairs."""
        found = contacts(model, data, adr, q).items()
        return sum(max(d - TOUCH, 0.0) for p, d in found if p not in always)

    def every(q) -> float:
        """m of penetration beyond TOUCH, summed over all pairs (the always ones too)."""
        return sum(max(d - TOUCH, 0.0) for d in contacts(model, data, adr, q).values())

    def search(q, score, done, frozen):
        """Greedy: one joint at a time (distal first) to the grid value that most improves
        `score(q)` (higher is better), until `done(best)`."""
        best = score(q)
        for _ in range(SWEEPS):
            for j, (lo, hi) in reversed(list(zip(movable, limits, strict=True))):
                if done(best):
                    return q
                if j.name in frozen or j.mimic is not None:
                    continue
                i = index[j.name]
                grid = np.linspace(lo, hi, GRID + 1)[1:-1]  # not at a limit, where a servo rests
                for value in sorted(grid, key=lambda v: abs(v - start[i])):
                    trial = q.copy()
                    trial[i] = value
                    trial = _follow(trial[None, :], movable, index)[0]
                    got = score(trial)
                    if better(got, best):
                        q, best = trial, got
        return q

    start = np.array(home, dtype=float)
    q = start
    if depth(q) > 0.0:
        feet = _feet_joints(robot, home, base_dir)
        q = search(q, lambda t: -depth(t), lambda b: b >= 0.0, feet)
        if depth(q) > 0.0:  # two joints at once for the pairs one cannot part
            args = (robot, model, data, adr, always, feet, limits, index)
            q = _pair_search(q, depth, *args)
        if depth(q) > 0.0:  # alike joints of all limbs together, feet kept level (quadrupeds)
            q = _alike(q, depth, robot, index, movable)
        if depth(q) > 0.0:  # not free: the first guess stays
            q = start
        elif always:  # "always" here may be "nearly always" to the kit's 10000 samples
            q = search(q, lambda t: (-depth(t), -every(t)), lambda b: b[1] >= 0.0, feet)
    support = Support(robot, base_dir) if rest else None
    if support is not None and support.margin(q) < MARGIN:
        q = _resting(q, support, depth, movable, limits, index)
    changes = [
        f"{j.name}: {start[i]:.4g} -> {q[i]:.4g}"
        for i, j in enumerate(movable)
        if abs(q[i] - start[i]) > 1e-12
    ]
    return ([float(f"{v:.6g}") for v in q], changes) if changes else None
