"""The importer's collision kernel: a collision-only MuJoCo model of a resolved robot and the
measures the pose searches take on it (home.py, gravity.py, limits.py, settle.py, stance.py).

Links collide with their collision geometry as the kit will: primitives, the convex hull of
each given collision mesh, else of each visual piece (`collision_shapes`), optionally with
the visual pieces the kit grows its collision pieces to cover (`covered_shapes`). Links
joined by a joint, or through links without geometry, never collide (`adjacent`), as in the
kit. Each geom has half of `CLEARANCE` as margin, so contacts report pairs closer than it.
Lengths in m, angles in rad, poses in spec order (`robot.movable_joints`).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from simkit.importer.fixups.scratch import Scratch, compiled, text
from simkit.model.kinematics import contracted_pairs

#: m: the clearance the chosen pose keeps between non-adjacent links (the kit's collision
#: pieces are grown a little to cover the visual mesh)
CLEARANCE = 0.003


def collision_shapes(link) -> tuple:
    """The shapes whose hulls stand for the link's collision geometry in the kit."""
    if link.collision_method == "primitives":  # none when the URDF gives no collision
        return link.collision_primitives
    if link.collision_shapes:
        return link.collision_shapes
    return link.shapes


def covered_shapes(link) -> tuple:
    """Collision shapes and, for a link that has some, its visual pieces too: the kit grows
    its collision pieces to cover the visual (a link without collision has none in the kit)."""
    given = tuple(collision_shapes(link))
    return given + tuple(s for s in link.shapes if s not in given) if given else ()


def adjacent(robot) -> set[tuple[str, str]]:
    """Links joined by a joint, or through links without geometry (the kit's exclusions)."""
    solid = {link.name for link in robot.links if collision_shapes(link)}
    joined = [(j.parent, j.child) for j in robot.joints]
    joined += [(lp.link1, lp.link2) for lp in robot.loops]  # a loop closure joins them too
    return contracted_pairs(joined, solid)


def model_xml(robot, base_dir: Path, also_excluded: tuple = (), shapes_of=collision_shapes) -> str:
    """The search's collision-only MJCF (scratch.py): geoms from `shapes_of(link)` with half
    the clearance as margin each, joined links, the pairs the source excludes
    (`contact_excludes`) and `also_excluded` pairs excluded, no parent filter."""
    margin = text([CLEARANCE / 2])  # MuJoCo adds the two geoms' margins
    scratch = Scratch(
        compiler={"angle": "radian"},
        geom={"contype": "1", "conaffinity": "1", "margin": margin},
        flags={"filterparent": "disable"},
    )
    scratch.tree(robot, base_dir, shapes_of)
    scratch.exclude(sorted(adjacent(robot) | set(also_excluded) | set(robot.contact_excludes)))
    return scratch.xml()


def penetration(model, data, adr, q) -> tuple[float, set[tuple[str, str]]]:
    """How far (m, summed over contacts) links are inside the clearance, and the link pairs."""
    import mujoco

    data.qpos[adr] = q
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    depth, pairs = 0.0, set()
    for i in range(data.ncon):
        if data.contact.dist[i] < CLEARANCE:
            depth += CLEARANCE - float(data.contact.dist[i])
            g1, g2 = data.contact.geom[i]
            pairs.add(
                (model.body(model.geom_bodyid[g1]).name, model.body(model.geom_bodyid[g2]).name)
            )
    return depth, pairs


def touching(data) -> bool:
    """True when the last `penetration` found two links touching or overlapping."""
    return bool((data.contact.dist[: data.ncon] <= 0.0).any())


def between(robot, a: str, b: str) -> list:
    """The movable joints on the tree path between links `a` and `b`, distal first."""
    parent = {j.child: j for j in robot.joints}

    def up(node: str) -> list:
        out = []
        while node in parent:
            out.append(parent[node])
            node = parent[node].parent
        return out

    ua, ub = up(a), up(b)
    common = {j.name for j in ua} & {j.name for j in ub}
    return [j for j in ua + ub if j.name not in common and j.movable and j.mimic is None]


#: random configurations (seeded) a pair's contact is counted in to tell an always pair
ALWAYS_SAMPLES = 200
#: the share of them it must touch in, and m: closer than this touches (the kit's rule,
#: derive/collision_pairs.py ALWAYS_FRACTION and TOUCH: MoveIt Setup Assistant's "Always")
ALWAYS_FRACTION = 0.95
TOUCH = 1e-6


def contacts(model, data, adr, q) -> set[tuple[str, str]]:
    """Link pairs (sorted names) touching or closer than `TOUCH` at `q`."""
    penetration(model, data, adr, q)
    out = set()
    for i in range(data.ncon):
        if data.contact.dist[i] < TOUCH:
            g1, g2 = data.contact.geom[i]
            a = model.body(model.geom_bodyid[g1]).name
            b = model.body(model.geom_bodyid[g2]).name
            out.add((a, b) if a < b else (b, a))
    return out


def always_touching(
    robot, base_dir: Path, start: np.ndarray, follow, shapes_of=collision_shapes
) -> tuple:
    """Link pairs touching at the first guess and in at least `ALWAYS_FRACTION` of
    `ALWAYS_SAMPLES` seeded random configurations: URDF collision shapes that overlap wherever
    (or almost wherever) the joints are (an arm's collision primitives of links 1 and 3, a
    gripper's fingertips in the hand's safety box, finger blocks face on face). The kit
    excludes such pairs (derive collision_pairs "always", as MoveIt Setup Assistant does), so
    no pose can or need separate them; the search must not try, or it never moves the pair it
    could fix."""
    movable = robot.movable_joints
    xml = model_xml(robot, base_dir, shapes_of=shapes_of)
    key = (xml, np.asarray(start, dtype=float).tobytes(), robot.seed, _motion(movable))
    if key not in _ALWAYS:  # the home search and its checks ask again for the same model
        if len(_ALWAYS) >= 16:
            _ALWAYS.clear()
        _ALWAYS[key] = _always_touching(xml, movable, robot.seed, start, follow)
    return _ALWAYS[key]


#: always_touching's answers by (model text, first guess, seed, joints' limits and mimics)
_ALWAYS: dict[tuple, tuple] = {}


def _motion(movable) -> tuple:
    """What the random configurations depend on besides the seed: limits and mimics."""
    return tuple((j.name, j.lower, j.upper, j.mimic) for j in movable)


def _always_touching(xml: str, movable, seed: int, start: np.ndarray, follow) -> tuple:
    model, data, adr = compiled(xml, movable)
    pairs = contacts(model, data, adr, start)
    rng = np.random.default_rng(seed)
    low = np.array([j.lower if j.lower is not None else -math.pi for j in movable])
    high = np.array([j.upper if j.upper is not None else math.pi for j in movable])
    allowed = ALWAYS_SAMPLES - math.ceil(ALWAYS_FRACTION * ALWAYS_SAMPLES - 1e-9)
    misses = dict.fromkeys(pairs, 0)
    for _ in range(ALWAYS_SAMPLES if pairs else 0):
        found = contacts(model, data, adr, follow(rng.uniform(low, high)))
        for p in misses:
            misses[p] += p not in found
    return tuple(sorted(p for p, n in misses.items() if n <= allowed))


def within_limits(movable, q: np.ndarray) -> bool:
    """Every joint of `q` (spec order) inside its limits (a mimic joint has its own)."""
    return all(
        (j.lower is None or value >= j.lower - 1e-9)
        and (j.upper is None or value <= j.upper + 1e-9)
        for j, value in zip(movable, q, strict=True)
    )


def posed(robot):
    """(home or None when the robot has no movable joint, follow): the home pose (spec order)
    and a function setting each mimic joint of a pose from its leader (the kit's equality)."""
    movable = robot.movable_joints
    index = {j.name: i for i, j in enumerate(movable)}

    def follow(q: np.ndarray) -> np.ndarray:
        for j in movable:
            if j.mimic is not None and j.mimic[0] in index:
                leader, multiplier, offset = j.mimic
                q[index[j.name]] = multiplier * q[index[leader]] + offset
        return q

    poses = dict(robot.poses)
    start = np.array(poses["home"], dtype=float) if "home" in poses else None
    return start, follow
