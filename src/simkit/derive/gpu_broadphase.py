"""MJX's broad phase for the GPU scene: the custom numeric `max_geom_pairs` (issue 30).

MJX runs the narrow phase of every explicit pair at every step, grouped by the two geom types
(one collision function per group). With `max_geom_pairs` = k it first keeps, in each group
of more than k pairs, the k pairs whose bounding spheres are nearest (centre distance less
both radii; MuJoCo's `geom_rbound`); plane pairs are exempt. A robot arm's self pairs are
mostly far apart: on an H100-class GPU the Rosie arms spent most of a step in narrow phases of
pairs that could not touch.

k holds beyond the sample that chose it, at a stated confidence (issue 42, class 2). It starts
as the most pairs of one group whose bounding spheres come within `NEAR` in a named pose or a
sampled configuration that only touches (pairs within `NEAR`, none deeper than the contact
budget's depth). Then a second, independent draw within the joint limits runs until `RUN`
configurations in a row have no touching pair ranked beyond k; each configuration that has
one raises k to that configuration's crowding and starts the run again. With `RUN` draws and
no miss, the chance that a configuration drawn within the limits has a touching pair beyond
k is under 3 / `RUN` at 95 % confidence (the rule of three: (1 - p)^N = 0.05 gives
p = -ln(0.05) / N, about 3 / N). A sampled maximum alone did not hold: an arm of dense
collision spheres chose k = 2 from its touching samples, and an independent draw of 2,000
configurations found a touching pair at rank 9. Where the run does not finish within
`MAX_DRAWS`, or k reaches a group's size, no cull is written. check/gpu_broadphase.py draws
its own configurations from the written file and holds the misses to the stated bound.
"""

from __future__ import annotations

import numpy as np

from simkit.derive.collision_pairs import follow_mimics, sampled_joints
from simkit.derive.gpu_colliders import mujoco_type, never_collided, scratch_xml
from simkit.model.robot import Robot

#: m: pairs this close count as in contact, and bounding spheres this close as crowding
NEAR = 0.005
#: configurations in a row without a miss that k must hold for: a miss probability under
#: 3 / RUN (1.5e-4) per configuration at 95 % confidence; the check's 20,000 draws then expect
#: under 3 misses
RUN = 20_000
#: the most configurations the confirming draw may take before no cull is written
MAX_DRAWS = 60_000
#: configurations drawn at a time, and the stream (with the robot's seed) they come from,
#: apart from the SRDF's and the check's draws
BATCH = 2_000
STREAM = 42


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


def _scene(robot: Robot, colliders: list[dict], pairs: list[tuple]):
    """(model, data, MJX groups, pair index, sampled joints' qpos addresses) of the scratch
    model with every geom's margin at `NEAR` / 2 (MuJoCo adds both geoms' margins)."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(scratch_xml(robot, colliders, never_collided(robot)))
    model.geom_margin[:] = NEAR / 2
    gid = {model.geom(i).name: i for i in range(model.ngeom)}
    ids = [(gid[a], gid[b], group) for a, b, group in pairs]
    index = {frozenset(p[:2]): i for i, p in enumerate(ids)}
    names = [j for j, _, _ in sampled_joints(robot)]
    adr = np.array([model.jnt_qposadr[model.joint(n).id] for n in names], dtype=int)
    return model, mujoco.MjData(model), grouped(ids), index, adr


def _seen(scene, robot: Robot, rows: np.ndarray, depth: float):
    """(row index, crowding, worst rank) of each configuration of `rows` that only touches."""
    import mujoco

    model, data, groups, index, adr = scene
    for i, row in enumerate(follow_mimics(robot, rows) if len(adr) and index else []):
        data.qpos[adr] = row
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        touching = _touching(data, index, depth)
        if touching:
            yield (i, *crowding(data.geom_xpos, model.geom_rbound, groups, touching))


def _draws(robot: Robot, batch: int):
    """Seeded configurations within the joint limits, `batch` at a time, from their own
    stream (the robot's seed and `STREAM`)."""
    limits = np.array([(lo, hi) for _, lo, hi in sampled_joints(robot)], dtype=float)
    rng = np.random.default_rng((robot.seed, STREAM))
    while True:
        yield limits[:, 0] + rng.random((batch, len(limits))) * (limits[:, 1] - limits[:, 0])


def confirm(scene, robot: Robot, k: int, largest: int, depth: float) -> tuple[int | None, int]:
    """(k, configurations drawn) once `RUN` configurations in a row have no touching pair
    ranked beyond k; a miss raises k to its configuration's crowding and restarts the run. k
    is None where that takes more than `MAX_DRAWS` or k reaches `largest`."""
    run = drawn = 0
    for rows in _draws(robot, BATCH):
        for i, crowd, worst in _seen(scene, robot, rows, depth):
            if worst > k:
                k, run = max(crowd, worst), -1 - i  # the run restarts after row i
        run, drawn = run + len(rows), drawn + len(rows)
        if k >= largest or (run < RUN and drawn >= MAX_DRAWS):
            return None, drawn
        if run >= RUN:
            return k, drawn
    raise AssertionError("unreachable")  # _draws never ends


def max_geom_pairs(
    robot: Robot, colliders: list[dict], pairs: list[tuple], rows: np.ndarray, depth: float
) -> dict:
    """`max_geom_pairs` for `pairs` of `mjx_pairs`: k (None: no cull), the worst rank seen in
    `rows` (sampled-joint order), the confirming draw's size (`confirm`) and the sampled
    maximum it started from (`sampled`). `colliders` holds every geom the pairs name,
    stand-in boxes included."""
    scene = _scene(robot, colliders, pairs)
    crowd = worst = 0
    for _, most, rank in _seen(scene, robot, rows, depth):
        crowd, worst = max(crowd, most), max(worst, rank)
    largest = max((len(members) for members, _ in scene[2]), default=0)
    if not 0 < crowd < largest:
        return {"k": None, "rank": worst, "drawn": 0, "sampled": crowd}
    k, drawn = confirm(scene, robot, crowd, largest, depth)
    return {"k": k, "rank": worst, "drawn": drawn, "sampled": crowd}
