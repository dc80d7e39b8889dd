"""The GPU scene's MJX broad phase keeps the pairs that touch (issues 30, 42).

MJX's custom numeric `max_geom_pairs` = k keeps, in each group of pairs with the same two geom
types, the k pairs whose bounding spheres are nearest, and never narrow-phases the rest. This
check reads the written GPU scene, draws its own seeded configurations within the joint limits
(followers of joint equalities placed by their polynomial; a floating base where keyframe 0
puts it), and in each configuration that only touches (no pair deeper than `DEPTH`) requires
each pair in contact to rank within k of its group. The derive step chose k so that a
configuration drawn within the limits has a touching pair beyond k with probability under
3 / 20,000 at 95 % confidence (robot.json `gpu_scene.broadphase_draws`: 20,000 draws in a row
without one; issue 42, class 2). This draw is independent of the derive's: it counts its
configurations with such a miss and fails where more are seen than that bound allows (the
binomial tail beyond `ALPHA`). At the bound, 20,000 draws expect 3 misses and allow 10; a k
of 1 on a 7-axis arm of mesh hulls, whose configurations touch in 3 of 1,000, misses in about
18 and fails. (2,000 draws, the first size, allowed 3 and let that k pass.)
"""

from __future__ import annotations

import numpy as np

from simkit.check.findings import Finding, compare, require

CHECK = "gpu_scene"
#: seeded configurations drawn, and the draw's seed (20,000: under a second for each seed kit)
SAMPLES = 20_000
SEED = 30
#: m: a configuration with a pair deeper than this is one a servo never reaches; pairs closer
#: than `NEAR` count as in contact (a touch lies between two draws)
DEPTH = 0.005
NEAR = 0.005
#: rad, m: the draw's range for a joint without limits
UNLIMITED = np.pi
#: the miss probability a written k holds to (derive/gpu_broadphase.py's 3 / RUN: the kit
#: states it, the check holds every kit to the same figure rather than to the kit's word)
MISS_BOUND = 3 / 20_000
#: the chance that a k that meets the bound fails the check anyway
ALPHA = 1e-3


def numeric(model, name: str) -> int | None:
    """The model's custom numeric `name`, or None."""
    import mujoco

    index = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
    return None if index < 0 else int(model.numeric_data[model.numeric_adr[index]])


def pair_groups(model) -> list[tuple[list[int], np.ndarray]]:
    """(explicit pair indices, their geom id pairs) by the pairs' two geom types, planes and
    height fields left out (MJX never culls those); groups sorted by type."""
    import mujoco

    exempt = {int(mujoco.mjtGeom.mjGEOM_PLANE), int(mujoco.mjtGeom.mjGEOM_HFIELD)}
    by_types: dict[tuple, list[int]] = {}
    for i in range(model.npair):
        pair = (model.pair_geom1[i], model.pair_geom2[i])
        types = tuple(sorted(int(model.geom_type[g]) for g in pair))
        if not set(types) & exempt:
            by_types.setdefault(types, []).append(i)
    return [
        (members, np.array([(model.pair_geom1[i], model.pair_geom2[i]) for i in members]))
        for _, members in sorted(by_types.items())
    ]


def configurations(model, samples: int, seed: int) -> np.ndarray:
    """Keyframes, then `samples` seeded joint positions within limits (qpos rows); free and
    ball joints stay at keyframe 0, joint-equality followers follow their leaders."""
    import mujoco

    base = model.key_qpos[0].copy() if model.nkey else model.qpos0.copy()
    rng = np.random.default_rng(seed)
    rows = np.repeat(base[None, :], samples, axis=0)
    moving = {int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)}
    for j in range(model.njnt):
        if int(model.jnt_type[j]) not in moving:
            continue
        low, high = model.jnt_range[j] if model.jnt_limited[j] else (-UNLIMITED, UNLIMITED)
        rows[:, model.jnt_qposadr[j]] = rng.uniform(low, high, samples)
    for e in range(model.neq):
        if int(model.eq_type[e]) == int(mujoco.mjtEq.mjEQ_JOINT) and model.eq_obj2id[e] >= 0:
            a, b = (model.jnt_qposadr[model.eq_obj1id[e]], model.jnt_qposadr[model.eq_obj2id[e]])
            c = model.eq_data[e, :5]
            x = rows[:, b] - model.qpos0[b]
            rows[:, a] = model.qpos0[a] + c[0] + c[1] * x + c[2] * x**2 + c[3] * x**3 + c[4] * x**4
    return np.vstack([model.key_qpos, rows]) if model.nkey else rows


def ranks(data, rbound: np.ndarray, groups: list, touching: set[int]) -> int:
    """The worst rank by bounding-sphere distance, within its group (`pair_groups`), of a
    touching pair."""
    worst = 0
    for members, ids in groups:
        xpos = data.geom_xpos
        gap = np.linalg.norm(xpos[ids[:, 0]] - xpos[ids[:, 1]], axis=1) - rbound[ids].sum(axis=1)
        for k, i in enumerate(members):
            if i in touching:
                worst = max(worst, int(np.count_nonzero(gap <= gap[k])))
    return worst


def misses(model, samples: int = SAMPLES, seed: int = SEED) -> tuple[int, int, int]:
    """(configurations with a touching pair ranked beyond max_geom_pairs, the worst rank of a
    touching pair, configurations that only touch) over the keyframes and the seeded draw."""
    import copy

    import mujoco

    cull = numeric(model, "max_geom_pairs")
    model = copy.deepcopy(model)
    model.pair_margin[:] = NEAR
    data = mujoco.MjData(model)
    groups = pair_groups(model)
    index = {
        frozenset((int(model.pair_geom1[i]), int(model.pair_geom2[i]))): i
        for members, _ in groups
        for i in members
    }
    missed = worst = touched = 0
    for row in configurations(model, samples, seed) if index else []:
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        contacts = data.contact[: data.ncon] if data.ncon else None
        if contacts is None or (-contacts.dist > DEPTH).any():
            continue
        touching = {index.get(frozenset(int(g) for g in pair)) for pair in contacts.geom}
        touching.discard(None)
        if touching:
            rank = ranks(data, model.geom_rbound, groups, touching)  # type: ignore[arg-type]
            worst, touched = max(worst, rank), touched + 1
            missed += cull is not None and rank > cull
    return missed, worst, touched


def allowed_misses(draws: int, bound: float = MISS_BOUND, alpha: float = ALPHA) -> int:
    """The most misses `draws` configurations show with probability over 1 - `alpha` when each
    misses with probability `bound` (the binomial quantile)."""
    from scipy.stats import binom

    return int(binom.ppf(1.0 - alpha, draws, bound))


def check_broadphase(gpu, doc: dict) -> list[Finding]:
    """`max_geom_pairs` is robot.json's, and keeps the pairs the draw finds in contact within
    the bound it was derived to (`MISS_BOUND`)."""
    stated = (doc.get("gpu_scene") or {}).get("max_geom_pairs")
    cull = numeric(gpu, "max_geom_pairs")
    out = [
        compare(
            CHECK,
            "max_geom_pairs as robot.json states",
            -1 if stated is None else stated,
            -1 if cull is None else cull,
            0,
            "",
        )
    ]
    if cull is None:
        return out
    missed, worst, touched = misses(gpu)
    draws = SAMPLES + gpu.nkey
    allowed = allowed_misses(draws)
    message = (
        f"MJX's broad phase keeps the pairs in contact: {missed} of {draws} configurations "
        f"({touched} only touch) have a touching pair beyond max_geom_pairs {cull} (worst rank "
        f"{worst}); at most {allowed} under a miss probability of {MISS_BOUND:.2g}"
    )
    return [*out, require(CHECK, missed <= allowed, message)]
