"""Self-collision of a kit's MuJoCo model: penetration depths, clearance, free joint ranges.

Every function takes an `MjModel` loaded from the kit's MJCF on disk (its own collision geoms,
contact excludes and parent-child filter, as a user's simulation sees them) plus plain data,
and returns plain data. Contacts with the world body (a floor) are not self-collision and are
ignored. Depths and distances are in metres, angles in radians.

Why MuJoCo: the issue (12) asks for the contacts a user of the kit would get; MuJoCo's own
collision pipeline with the MJCF's filters is exactly that.

Mimic joints move with their leaders (the MJCF's equality constraints hold them so): every
configuration tried sets each follower to `multiplier x leader + offset` (`coupled`), and a
follower's free range is its leader's, mapped (issue 32: a gripper's knuckle swept alone,
its mimic partners still, met configurations the mechanism never reaches).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from simkit.kitio import layout
from simkit.kitio.fmt import rounded
from simkit.model.robot import Robot
from simkit.simulate.loaders import load_mjcf_file

#: Penetration (m) above which two bodies count as colliding (issue 12: "more than 1 mm").
TOLERANCE = 0.001
#: Sweep step for the free ranges (rad): 0.5 deg, finer than the check's 2 deg sweeps.
RANGE_STEP = 0.5 * 3.141592653589793 / 180.0
#: Random configurations for the self-contact fraction, and their default seed.
SAMPLES = 10_000


#: a mimic joint among the joints tried: (its index, its leader's index, multiplier, offset)
Mimic = tuple[int, int, float, float]


def mimics_of(names: Sequence[str], mimic: dict[str, tuple[str, float, float]]) -> list[Mimic]:
    """The `Mimic`s of joints `names` from {follower: (leader, multiplier, offset)}; a
    follower whose leader is not among `names` is left free."""
    index = {name: i for i, name in enumerate(names)}
    return [
        (index[f], index[leader], float(m), float(o))
        for f, (leader, m, o) in mimic.items()
        if f in index and leader in index
    ]


def coupled(q: Sequence[float], mimics: Sequence[Mimic]) -> list[float]:
    """`q` with each mimic joint at multiplier x its leader's value + offset (a leader that
    follows another is set first: one pass per link of the longest chain)."""
    out = [float(v) for v in q]
    for _ in range(len(mimics)):
        before = list(out)
        for follower, leader, multiplier, offset in mimics:
            out[follower] = multiplier * out[leader] + offset
        if out == before:
            break
    return out


@dataclass(frozen=True)
class Contact:
    """The deepest penetration between two bodies (names sorted), depth in metres (> 0)."""

    body1: str
    body2: str
    depth: float


def joint_addresses(model, joints: Sequence[str]) -> list[int]:
    """qpos address of each named hinge/slide joint (KeyError names a missing joint)."""
    import mujoco

    out = []
    for name in joints:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid < 0:
            raise KeyError(f"joint '{name}' is not in the MJCF")
        out.append(int(model.jnt_qposadr[jid]))
    return out


def contacts(model, data, adr: Sequence[int], q: Sequence[float]) -> list[Contact]:
    """Self-contacts at joint values `q` (rad, at addresses `adr`; other qpos from `data`),
    one per body pair with its deepest penetration, deepest first."""
    import mujoco

    for a, value in zip(adr, q, strict=True):
        data.qpos[a] = value
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    deepest: dict[tuple[str, str], float] = {}
    for i in range(data.ncon):
        con = data.contact[i]
        b1, b2 = int(model.geom_bodyid[con.geom[0]]), int(model.geom_bodyid[con.geom[1]])
        if b1 == 0 or b2 == 0 or con.dist >= 0:
            continue
        n1, n2 = sorted((model.body(b1).name, model.body(b2).name))
        deepest[(n1, n2)] = max(deepest.get((n1, n2), 0.0), float(-con.dist))
    found = [Contact(a, b, d) for (a, b), d in deepest.items()]
    return sorted(found, key=lambda c: (-c.depth, c.body1, c.body2))


def worst(
    model, data, adr: Sequence[int], q: Sequence[float], mimics: Sequence[Mimic] = ()
) -> Contact | None:
    """The deepest self-contact at `q` (mimic joints moved with their leaders), or None."""
    found = contacts(model, data, adr, coupled(q, mimics) if mimics else q)
    return found[0] if found else None


def _checked_pairs(model) -> list[tuple[int, int]]:
    """Collision geom pairs MuJoCo would test for self-collision: different bodies, neither
    the world, not welded together, not parent and child, not excluded, compatible masks."""
    excluded = {int(s) for s in model.exclude_signature}
    geoms = [
        g
        for g in range(model.ngeom)
        if (model.geom_contype[g] or model.geom_conaffinity[g]) and model.geom_bodyid[g] != 0
    ]
    pairs = []
    for i, g1 in enumerate(geoms):
        for g2 in geoms[i + 1 :]:
            b1, b2 = sorted((int(model.geom_bodyid[g1]), int(model.geom_bodyid[g2])))
            w1, w2 = int(model.body_weldid[b1]), int(model.body_weldid[b2])
            if w1 == w2 or (b1 << 16) + b2 in excluded:
                continue
            if model.body_parentid[w2] == w1 or model.body_parentid[w1] == w2:
                continue
            if not (
                model.geom_contype[g1] & model.geom_conaffinity[g2]
                or model.geom_contype[g2] & model.geom_conaffinity[g1]
            ):
                continue
            pairs.append((g1, g2))
    return pairs


def min_clearance(model, data, adr: Sequence[int], q: Sequence[float], distmax: float = 1.0):
    """(distance m, body1, body2) of the closest pair of self-colliding bodies at `q`;
    negative when they penetrate. None when the model has no such pair."""
    import mujoco

    for a, value in zip(adr, q, strict=True):
        data.qpos[a] = value
    mujoco.mj_kinematics(model, data)
    best = None
    for g1, g2 in _checked_pairs(model):
        dist = float(mujoco.mj_geomDistance(model, data, g1, g2, distmax, None))
        if best is None or dist < best[0]:
            names = sorted(model.body(int(model.geom_bodyid[g])).name for g in (g1, g2))
            best = (dist, names[0], names[1])
    return best


def free_range(
    model,
    data,
    adr: Sequence[int],
    home: Sequence[float],
    index: int,
    lower: float,
    upper: float,
    step: float = RANGE_STEP,
    tol: float = TOLERANCE,
    mimics: Sequence[Mimic] = (),
) -> tuple[float, float]:
    """Collision-free range (rad) of joint `index` about `home`, the others at home: from home
    toward each limit in `step`s, up to the last angle before a penetration deeper than `tol`
    (the limit itself when none). Home itself is assumed free. Each angle is tried as
    robot.json publishes it (10 significant digits): at a grazing edge MuJoCo's depth jumps
    (0.5 mm to 2.8 mm for 1e-10 rad on the imported quadruped), and the check tries the
    published end."""
    import math

    q = list(home)
    ends = []
    for limit in (lower, upper):
        span = limit - home[index]
        count = max(1, math.ceil(abs(span) / step))
        last = home[index]
        for k in range(1, count + 1):
            q[index] = limit if k == count else rounded(home[index] + span * k / count)
            hit = worst(model, data, adr, q, mimics)
            if hit is not None and hit.depth > tol:
                break
            last = q[index]
        ends.append(last)
    return ends[0], ends[1]


def contact_fraction(
    model,
    data,
    adr: Sequence[int],
    lower: Sequence[float],
    upper: Sequence[float],
    seed: int,
    samples: int = SAMPLES,
    tol: float = TOLERANCE,
    mimics: Sequence[Mimic] = (),
) -> float:
    """Share of `samples` uniform random configurations inside the limits (numpy generator
    seeded with `seed`) with a self-penetration deeper than `tol`."""
    import numpy as np

    rng = np.random.default_rng(seed)
    qs = rng.uniform(np.asarray(lower), np.asarray(upper), size=(samples, len(adr)))
    hits = 0
    for q in qs:
        hit = worst(model, data, adr, q, mimics)
        hits += hit is not None and hit.depth > tol
    return hits / samples


def summary(
    model,
    joints: Sequence[str],
    lower: Sequence[float],
    upper: Sequence[float],
    home: Sequence[float],
    seed: int,
    samples: int = SAMPLES,
    tol: float = TOLERANCE,
    mimics: Sequence[Mimic] = (),
) -> dict:
    """robot.json `geometry.self_collision`: clearance at home, each joint's free range about
    home, and the self-contact fraction of `samples` seeded random configurations; mimic
    joints move with their leaders, and a follower's free range is its leader's, mapped."""
    import mujoco

    data = mujoco.MjData(model)
    adr = joint_addresses(model, joints)
    clearance = min_clearance(model, data, adr, coupled(home, mimics))
    spans: dict[int, tuple[float, float]] = {}
    followers = {f: (leader, m, o) for f, leader, m, o in mimics}
    for i in range(len(joints)):
        if i not in followers:
            spans[i] = free_range(
                model, data, adr, home, i, lower[i], upper[i], tol=tol, mimics=mimics
            )
    for _ in range(len(followers)):  # a follower's leader may follow another: in turn
        for i, (leader, m, o) in followers.items():
            if i not in spans and leader in spans:
                ends = sorted(m * end + o for end in spans[leader])
                spans[i] = (rounded(ends[0]), rounded(ends[1]))
    ranges = []
    for i, name in enumerate(joints):
        lo, hi = spans.get(i, (lower[i], upper[i]))  # a mimic cycle: its limits
        ranges.append(
            {
                "joint": name,
                "lower": lo,
                "upper": hi,
                "limited_by_collision": bool(lo > lower[i] or hi < upper[i]),
            }
        )
    fraction = contact_fraction(model, data, adr, lower, upper, seed, samples, tol, mimics)
    return {
        "method": "MuJoCo contacts on the MJCF's collision geoms with its excludes and "
        "parent-child filter; contacts with the world body ignored",
        "tolerance_m": tol,
        "home_min_clearance_m": None if clearance is None else clearance[0],
        "home_closest_pair": None if clearance is None else [clearance[1], clearance[2]],
        "free_range_step_rad": RANGE_STEP,
        "free_ranges": ranges,
        "random_samples": samples,
        "random_seed": seed,
        "random_contact_fraction": fraction,
    }


def run(kit_dir: Path, robot: Robot) -> dict:
    """robot.json `geometry.self_collision` for the kit staged at `kit_dir`: MuJoCo on its
    MJCF, joint limits and home as robot.json publishes them (10 significant digits), the
    spec's seed for the random configurations."""
    model = load_mjcf_file(kit_dir / layout.mjcf(robot.name))
    moving = robot.movable_joints
    lower = [-math.pi if j.lower is None else rounded(j.lower) for j in moving]
    upper = [math.pi if j.upper is None else rounded(j.upper) for j in moving]
    poses = dict(robot.poses)
    home = [rounded(v) for v in poses["home"]] if "home" in poses else [0.0] * len(moving)
    names = [j.name for j in moving]
    mimics = mimics_of(names, {j.name: j.mimic for j in moving if j.mimic is not None})
    return summary(model, names, lower, upper, home, robot.seed, mimics=mimics)
