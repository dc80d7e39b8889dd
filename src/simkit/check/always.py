"""The pairs robot.json lists as in contact in every configuration (`collision_pairs.always`,
which the MJCF excludes) really do touch: in the sampled configurations regenerated from the
recorded seed (derive/collision_pairs.py's METHOD) with mimic joints following their leaders,
some geom of one link penetrates (or is within `always_rule.touch` of) some geom of the other
in the kit's own MJCF, in at least `always_rule.fraction` of the first `always_rule.samples`
configurations (MoveIt Setup Assistant's min_collision_fraction; a kit without the rule:
every one of the first `PROBES`, and at home). So a pair cannot be excluded from contact
unless its collision geometry overlaps wherever, or almost wherever, the joints are.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from simkit.check.kit import Kit

PROBES = 10  # sampled configurations tested besides home (a kit without `always_rule`)
#: the share of the derive stage's count a pair must reach here: the kit's mesh files are
#: float32, so a pair at the edge of the rule may lose a contact or two
SLACK = 0.99


def body_geoms(model: mujoco.MjModel, body: str) -> list[int]:
    bid = model.body(body).id
    return [g for g in range(model.ngeom) if model.geom_bodyid[g] == bid and model.geom_contype[g]]


def pair_depth(model, data, a: list[int], b: list[int], touch: float = 0.0) -> float:
    """Deepest penetration (m, <= -touch when apart) between two geom sets."""
    fromto = np.zeros(6)
    return max(
        (-mujoco.mj_geomDistance(model, data, g1, g2, 2 * touch, fromto) for g1 in a for g2 in b),
        default=-math.inf,
    )


def not_touching(kit: Kit, model: mujoco.MjModel) -> list[str]:
    """`a b (where)` for each listed always pair found apart; [] when every one touches."""
    block = kit.doc.get("collision_pairs") or {}
    pairs = block.get("always", [])
    if not pairs:
        return []
    rule = block.get("always_rule")
    joints = {j["name"]: j for j in kit.joints}
    names = block["joints"]
    # the recorded draws (collision_pairs.method); check never imports derive
    count = rule["samples"] if rule else PROBES
    unit = np.random.default_rng(block["seed"]).random((block["samples"], len(names)))[:count]
    home = dict(zip([j["name"] for j in kit.joints], kit.doc.get("home") or [], strict=False))
    configs = [] if rule else [("home", home)]
    for k, u in enumerate(unit):
        q = {}
        for name, x in zip(names, u, strict=True):
            j = joints[name]
            lo, hi = (j["lower"], j["upper"]) if j["lower"] is not None else (-math.pi, math.pi)
            if j["type"] == "continuous":
                lo, hi = -math.pi, math.pi
            q[name] = lo + x * (hi - lo)
        for name in names:  # mimic joints follow their leaders (the MJCF's equality)
            mimic = joints[name].get("mimic")
            if mimic and mimic["joint"] in q:
                q[name] = mimic["multiplier"] * q[mimic["joint"]] + mimic["offset"]
        configs.append((f"sample {k}", q))
    touch = rule["touch"] if rule else 0.0
    data = mujoco.MjData(model)
    geoms = {p: (body_geoms(model, p[0]), body_geoms(model, p[1])) for p in map(tuple, pairs)}
    misses: dict[tuple, list[str]] = {p: [] for p in geoms}
    for where, q in configs:
        data.qpos[:] = model.qpos0
        for name, value in q.items():
            data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
        mujoco.mj_kinematics(model, data)
        for p, (a, b) in geoms.items():
            if pair_depth(model, data, a, b, touch) <= -touch:
                misses[p].append(where)
    # at most this many configurations apart (none without the rule)
    allowed = len(configs) - math.ceil(SLACK * rule["fraction"] * len(configs)) if rule else 0
    return [
        f"{a} {b} ({', '.join(where[:3])}{' ...' if len(where) > 3 else ''}: "
        f"{len(where)} of {len(configs)} apart)"
        for (a, b), where in misses.items()
        if len(where) > allowed
    ]
