"""MJX's broad phase for the GPU scene: the custom numeric `max_geom_pairs` (issue 30).

MJX runs the narrow phase of every explicit pair at every step, grouped by the two geom types
(one collision function per group). With `max_geom_pairs` = k it first keeps, in each group
of more than k pairs, the k pairs whose bounding spheres are nearest (centre distance less
both radii; MuJoCo's `geom_rbound`); plane pairs are exempt. A robot arm's self pairs are
mostly far apart: on an H100-class GPU the Rosie arms spent most of a step in narrow phases of
pairs that could not touch.

k comes from the same samples as the pairs: in every named pose and every sampled
configuration that only touches (pairs within `NEAR`, none deeper than the contact budget's
depth), k is the most pairs of one group whose bounding spheres come within `NEAR` of each
other. A pair in contact is among those, so it ranks within k. The worst rank itself is a
heavy-tailed statistic (one seeded draw of 20,000 configurations put an Asimov pair at rank
46 where the derive's draw saw 11), so k is this bound and not a multiple of that rank. No
cull is written where k would keep every group whole. check/gpu_broadphase.py draws its own
configurations from the written file and requires every touching pair to rank within k.
"""

from __future__ import annotations

import numpy as np

from simkit.derive.collision_pairs import follow_mimics, sampled_joints
from simkit.derive.gpu_colliders import mujoco_type, never_collided, scratch_xml
from simkit.model.robot import Robot

#: m: pairs this close count as in contact, and bounding spheres this close as crowding
NEAR = 0.005


def mjx_pairs(pairs: list[list[str]], kinds: dict[str, str], swaps: dict) -> list[tuple]:
    """The pairs as MJX sees them: (geom, geom, group) with a cylinder's stand-in box named
    `NAME_box` where it meets that partner; the group is the two MuJoCo geom types, sorted."""
    out = []
    for a, b in pairs:
        names, types = [], []
        for x, y in ((a, b), (b, a)):
            boxed = y in swaps.get(x, ())
            names.append(f"{x}_box" if boxed else x)
            types.append("box" if boxed else mujoco_type(kinds[x]))
        out.append((names[0], names[1], tuple(sorted(types))))
    return out


def _gaps(xpos: np.ndarray, rbound: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """Bounding-sphere gaps (m) of geom id pairs: centre distance less both radii."""
    return np.linalg.norm(xpos[ids[:, 0]] - xpos[ids[:, 1]], axis=1) - rbound[ids].sum(axis=1)


def grouped(pairs: list[tuple]) -> list[tuple[list[int], np.ndarray]]:
    """(indices into `pairs`, their geom id pairs) of each MJX group, groups sorted; `pairs`
    are (geom id, geom id, group)."""
    out = []
    for group in sorted({p[2] for p in pairs}):
        members = [i for i, p in enumerate(pairs) if p[2] == group]
        out.append((members, np.array([pairs[i][:2] for i in members], dtype=int)))
    return out


def crowding(xpos: np.ndarray, rbound: np.ndarray, groups: list, touching) -> tuple[int, int]:
    """(the most pairs of one group whose bounding spheres come within `NEAR`, the worst rank
    of a pair in `touching` within its group); `groups` as `grouped` gives them. A pair in
    contact has a gap under NEAR, so its rank is at most the first number."""
    crowd = worst = 0
    for members, ids in groups:
        gap = _gaps(xpos, rbound, ids)
        crowd = max(crowd, int(np.count_nonzero(gap <= NEAR)))
        for k, i in enumerate(members):
            if i in touching:  # ties count against the pair
                worst = max(worst, int(np.count_nonzero(gap <= gap[k])))
    return crowd, worst


def _touching(data, index: dict, depth: float) -> set[int] | None:
    """Indices of the pairs in contact (`index`: geom id pair -> pair index), or None where
    one penetrates deeper than `depth`."""
    out = set()
    for c in range(data.ncon):
        i = index.get(frozenset(int(g) for g in data.contact.geom[c]))
        if i is not None:
            if -data.contact.dist[c] > depth:
                return None
            out.add(i)
    return out


def max_geom_pairs(
    robot: Robot, colliders: list[dict], pairs: list[tuple], rows: np.ndarray, depth: float
) -> tuple[int | None, int]:
    """(k, the worst rank seen) for `pairs` of `mjx_pairs` over configurations `rows` (in
    sampled-joint order) that only touch (pairs within `NEAR`, none deeper than `depth`); k is
    None where it would cull nothing. `colliders` holds every geom the pairs name, stand-in
    boxes included."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(scratch_xml(robot, colliders, never_collided(robot)))
    model.geom_margin[:] = NEAR / 2  # MuJoCo adds both geoms' margins
    data = mujoco.MjData(model)
    gid = {model.geom(i).name: i for i in range(model.ngeom)}
    ids = [(gid[a], gid[b], group) for a, b, group in pairs]
    groups = grouped(ids)
    index = {frozenset(p[:2]): i for i, p in enumerate(ids)}
    names = [j for j, _, _ in sampled_joints(robot)]
    adr = np.array([model.jnt_qposadr[model.joint(n).id] for n in names], dtype=int)
    crowd = worst = 0
    for row in follow_mimics(robot, rows) if len(names) and ids else []:
        data.qpos[adr] = row
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        touching = _touching(data, index, depth)
        if touching:
            seen = crowding(data.geom_xpos, model.geom_rbound, groups, touching)
            crowd, worst = max(crowd, seen[0]), max(worst, seen[1])
    largest = max((len(members) for members, _ in groups), default=0)
    return (crowd if 0 < crowd < largest else None), worst
