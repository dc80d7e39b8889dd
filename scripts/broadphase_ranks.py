"""How crowded a GPU scene's MJX pair groups get (issues 30, 42): over seeded configurations
that only touch, the worst rank of a touching pair within its group by bounding-sphere
distance, and the most pairs of one group whose bounding spheres come within 5 mm (where
`max_geom_pairs` starts); `misses`: configurations with a touching pair ranked beyond the
file's `max_geom_pairs`, against `allowed`, what the check allows that many draws under the
stated bound (3 in 20,000). One JSON line per kit and seed.

    python scripts/broadphase_ranks.py KIT... [--samples 20000] [--seeds 11 12 13]
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
from pathlib import Path

import mujoco
import numpy as np

from simkit.check import gpu_broadphase as bp


def crowding(model, data, groups: dict) -> int:
    """The most pairs of one group whose bounding spheres come within `bp.NEAR` (m)."""
    most = 0
    for _, ids in groups:
        centre = np.linalg.norm(data.geom_xpos[ids[:, 0]] - data.geom_xpos[ids[:, 1]], axis=1)
        most = max(most, int(np.count_nonzero(centre - model.geom_rbound[ids].sum(1) <= bp.NEAR)))
    return most


def survey(path: Path, samples: int, seed: int) -> dict:
    model = copy.deepcopy(mujoco.MjModel.from_xml_path(str(path)))
    model.pair_margin[:] = bp.NEAR
    data = mujoco.MjData(model)
    groups = bp.pair_groups(model)
    index = {
        frozenset((int(model.pair_geom1[i]), int(model.pair_geom2[i]))): i
        for i in range(model.npair)
    }
    ranks, crowds = [], []
    for row in bp.configurations(model, samples, seed):
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        contacts = data.contact[: data.ncon]
        if not data.ncon or (-contacts.dist > bp.DEPTH).any():
            continue
        touching = {index.get(frozenset(int(g) for g in p)) for p in contacts.geom} - {None}
        if touching:
            ranks.append(bp.ranks(data, model.geom_rbound, groups, touching))
            crowds.append(crowding(model, data, groups))
    cull = bp.numeric(model, "max_geom_pairs")
    return {
        "file": path.name,
        "seed": seed,
        "touching_configurations": len(ranks),
        "worst_rank": max(ranks, default=0),
        "rank_p99": float(np.percentile(ranks, 99)) if ranks else 0.0,
        "most_crowded": max(crowds, default=0),
        "max_geom_pairs": cull,
        "misses": sum(r > cull for r in ranks) if cull is not None else 0,
        "allowed": bp.allowed_misses(samples + model.nkey),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kits", nargs="+", type=Path)
    parser.add_argument("--samples", type=int, default=20000)
    parser.add_argument("--seeds", nargs="+", type=int, default=[11, 12, 13])
    args = parser.parse_args(argv)
    for kit in args.kits:
        doc = json.loads((kit / "robot.json").read_text(encoding="utf-8"))
        for seed in args.seeds:
            print(
                json.dumps(survey(kit / doc["files"]["mjcf_mjx"], args.samples, seed)), flush=True
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
