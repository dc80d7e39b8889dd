"""The pairs robot.json lists as in contact in every configuration (`collision_pairs.always`,
which the MJCF excludes) really do touch: at home and at the first sampled configurations,
regenerated from the recorded seed (derive/collision_pairs.py's METHOD) with mimic joints
following their leaders, some geom of one link penetrates some geom of the other in the kit's
own MJCF. So a pair cannot be excluded from contact unless its collision geometry overlaps
wherever the joints are.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from simkit.check.kit import Kit

PROBES = 10  # sampled configurations tested besides home


def _geoms(model: mujoco.MjModel, body: str) -> list[int]:
    bid = model.body(body).id
    return [g for g in range(model.ngeom) if model.geom_bodyid[g] == bid and model.geom_contype[g]]


def _depth(model, data, a: list[int], b: list[int]) -> float:
    """Deepest penetration (m, <= 0 when apart) between two geom sets."""
    fromto = np.zeros(6)
    return max(
        (-mujoco.mj_geomDistance(model, data, g1, g2, 0.0, fromto) for g1 in a for g2 in b),
        default=-math.inf,
    )


def not_touching(kit: Kit, model: mujoco.MjModel) -> list[str]:
    """`a b (where)` for each listed always pair found apart; [] when every one touches."""
    block = kit.doc.get("collision_pairs") or {}
    pairs = block.get("always", [])
    if not pairs:
        return []
    joints = {j["name"]: j for j in kit.joints}
    names = block["joints"]
    # the recorded draws (collision_pairs.method); check never imports derive
    unit = np.random.default_rng(block["seed"]).random((block["samples"], len(names)))[:PROBES]
    home = dict(zip([j["name"] for j in kit.joints], kit.doc.get("home") or [], strict=False))
    configs = [("home", home)]
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
    data = mujoco.MjData(model)
    apart = []
    for where, q in configs:
        data.qpos[:] = model.qpos0
        for name, value in q.items():
            data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
        mujoco.mj_kinematics(model, data)
        for a, b in pairs:
            if _depth(model, data, _geoms(model, a), _geoms(model, b)) <= 0.0:
                apart.append(f"{a} {b} ({where})")
    return apart
