"""The GPU scene's plan (`mjcf/NAME_mjx.xml`, issue 30): primitive colliders, explicit contact
pairs and solver settings for MJX and MuJoCo Warp; bodies, masses, joints and servos stay the
main MJCF's.

Why a second file: MJX and MuJoCo Warp give every geom pair that may touch static contact
slots, and collide convex meshes slowly (MJX documentation, "Performance tuning"); the main
MJCF keeps the kit page's rules (only adjacent links excluded, up to ten convex pieces a link).
Menagerie's `*_mjx.xml` files and MuJoCo Playground's variants do the same.

Colliders, per link (`colliders`):
- the spec's collision primitives, as in the main MJCF;
- a union of convex primitives (one `convex` piece per primitive): each primitive itself; a
  cone becomes the smallest cylinder that covers it;
- any other piece (CoACD, given hulls): the kit's own OBJ piece, its hull capped at
  `MAX_HULL_VERTICES` vertices (MuJoCo's `maxhullvert`).
MJX collides cylinders only with planes, spheres, capsules and cylinders: against a box or a
mesh, a cylinder's circumscribed box stands in for it, in that pair only (the inscribed box
where the circumscribed one would touch at a named pose that the cylinder does not). So no
collider turns into a mesh (MJX compiles one collision function per distinct mesh pair).

Pairs (`contact pairs`): the collider pairs in contact at a named pose or in any of the seeded
configurations the SRDF's sampling draws (derive/collision_pairs.py), except the link pairs
the main MJCF never collides (joined by a joint, welded, always in contact). A floating base
also meets a floor: every collider pairs with it, less those whose core lies in the convex
hull of a neighbour's core on the same link (a plane can never reach them first).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from simkit.derive.collision_pairs import configurations, sampled_joints
from simkit.derive.gpu_broadphase import RUN, max_geom_pairs, mjx_pairs
from simkit.derive.gpu_budget import capped_pairs, no_scene
from simkit.derive.gpu_colliders import (
    MAX_HULL_VERTICES,
    colliders,
    mujoco_type,
    never_collided,
    piece_vertices,
    sampled_contacts,
    scratch_xml,
)
from simkit.derive.gpu_solver import HOLD_TOLERANCE, fewest_iterations
from simkit.model.kinematics import rpy_matrix
from simkit.model.robot import Robot

#: contact slots a pair takes in MJX (mujoco-mjx 3.17 collision functions' `ncon`), by the
#: two MuJoCo geom types in MuJoCo's order; `mesh` stands for pieces
MJX_CONTACTS = {
    ("plane", "sphere"): 1,
    ("plane", "capsule"): 2,
    ("plane", "box"): 4,
    ("plane", "cylinder"): 3,
    ("plane", "mesh"): 4,
    ("sphere", "sphere"): 1,
    ("sphere", "capsule"): 1,
    ("sphere", "cylinder"): 1,
    ("sphere", "box"): 1,
    ("sphere", "mesh"): 1,
    ("capsule", "capsule"): 1,
    ("capsule", "box"): 2,
    ("capsule", "cylinder"): 2,
    ("capsule", "mesh"): 2,
    ("cylinder", "cylinder"): 4,
    ("box", "box"): 4,
    ("box", "mesh"): 4,
    ("mesh", "mesh"): 4,
}
TYPE_ORDER = ("plane", "sphere", "capsule", "cylinder", "box", "mesh")
#: a target for contact slots per world; a robot over it says so in one line (robot.json)
SLOT_TARGET = 64
#: the most explicit pairs (floor pairs included) a GPU scene carries. Asimov's 161 is the
#: largest seed scene (0.41-0.46x MJX's humanoid on an H200), a 7-axis arm of dense collision
#: spheres has about 450; an imported 74-joint humanoid's 1,489 self pairs asked for 5,956
#: contact slots a world, which no batch of thousands holds.
#: Over it, the self pairs are cut to those in contact at a named pose plus the ones most
#: often in contact in the samples, and robot.json says so in one line (issue 42, class 9)
MAX_PAIRS = 512
#: constraint rows per contact: condim 3 in a pyramidal cone (MuJoCo's defaults)
ROWS_PER_CONTACT = 4
#: the floor's name in pairs when the spec names none
FLOOR = "floor"
#: m: a sampled configuration penetrating no deeper than this only touches
TOUCHING_DEPTH = 0.005
#: hull vertices kept for a piece the robot stands on at home (MJX's guidance against a plane:
#: about 200; fewer would lower and narrow the feet, and the robot would drift), and how
#: close to the floor (m) a collider counts as standing on it
STANDING_HULL_VERTICES = 200
STANDING_MARGIN = 0.01


METHOD = (
    "colliders: the spec's primitives (a cone as the cylinder that covers it; a cylinder's "
    "circumscribed box where it meets a box or a mesh), other pieces with at most "
    f"{MAX_HULL_VERTICES} hull vertices ({STANDING_HULL_VERTICES} for pieces within "
    f"{STANDING_MARGIN} m of the floor at home); pairs: the collider pairs in contact in any of "
    "the named poses and `samples` configurations drawn as for collision_pairs (seed `seed`), "
    "less the pairs the main MJCF never collides; floor pairs (floating base): every collider "
    "whose core no same-link neighbour's covers; "
    "contact_slots: MJX slots of the floor pairs plus twice the most in use at once in a "
    f"sampled configuration that penetrates under {TOUCHING_DEPTH} m (MJX max_contact_points "
    f"keeps the deepest), at most pair_slots; njmax: {ROWS_PER_CONTACT} rows a contact plus "
    "joint limits, friction loss and mimics (MuJoCo Warp's sizes, custom numerics "
    "warp_nconmax and warp_njmax, so C MuJoCo and MJX size their own arena); max_geom_pairs "
    "(MJX's broad phase, absent: no cull): the most pairs of one MJX group whose bounding "
    "spheres come within 5 mm in a named pose or a sampled configuration that only touches "
    "(pairs within 5 mm), raised until broadphase_draws.run configurations in a row drawn "
    "within the limits have no touching pair ranked beyond it; broadphase_rank: the worst rank "
    "of a touching pair in the first samples; solver: the fewest iterations / ls_iterations "
    "(cheapest first of 1/2, 2/4, 3/6, 4/8, 6/12, 8/16, 16/32), at least the most MuJoCo's "
    "solver takes to converge in a step of the holds, for which the servos hold every named "
    "pose for 2 s in C MuJoCo with the scene's pairs within 2.5 mm of every contact at "
    "MuJoCo's default solver; hold_error_m: that distance"
)
#: the confidence robot.json states for max_geom_pairs (the rule of three, 95 %)
CONFIDENCE = (
    "a configuration drawn within the joint limits has a touching pair ranked beyond "
    "max_geom_pairs with probability under 3 / run (95 % confidence, the rule of three)"
)


def stand_ins(kinds: dict[str, str], pairs: list[list[str]]) -> dict[str, list[str]]:
    """Cylinders that meet a box or a mesh, with those partners: MJX has no collision function
    for such pairs, so there the cylinder's circumscribed box stands in for it."""
    out: dict[str, list[str]] = {}
    for a, b in pairs:
        for x, y in ((a, b), (b, a)):
            if kinds[x] == "cylinder" and mujoco_type(kinds.get(y, "plane")) in ("box", "mesh"):
                out.setdefault(x, []).append(y)
    return {k: sorted(v) for k, v in sorted(out.items())}


def stand_in_box(geom: dict, half: float) -> dict:
    """A cylinder's stand-in: the box of half side `half` (m) along its axis, its length."""
    size = [2 * half, 2 * half, geom["length"]]
    return {
        "link": geom["link"],
        "name": f"{geom['name']}_box",
        "kind": "box",
        "size": size,
        "xyz": geom["xyz"],
        "rpy": geom["rpy"],
        "class": geom.get("class"),
    }


def _named_rows(robot: Robot) -> np.ndarray:
    """Every named pose (zeros without any) in sampled-joint order."""
    names = [j.name for j in robot.movable_joints]
    order = [n for n, _, _ in sampled_joints(robot)]
    rows = [dict(zip(names, q, strict=True)) for _, q in robot.poses] or [{}]
    return np.array([[row.get(n, 0.0) for n in order] for row in rows], dtype=float)


def inscribed_stand_ins(robot: Robot, geoms: list[dict], swaps: dict) -> set[str]:
    """Cylinders whose circumscribed box touches a partner at a named pose where the cylinder
    does not: the servos hold those poses, so the box would push where the main MJCF has no
    contact. They get the inscribed box (inside the cylinder: it touches only where the
    cylinder does)."""
    by_name = {g["name"]: g for g in geoms}
    boxes = [stand_in_box(by_name[name], by_name[name]["radius"]) for name in swaps]
    out = set()
    for _depth, touching in sampled_contacts(robot, geoms + boxes, _named_rows(robot)):
        for name, partners in swaps.items():
            for partner in partners:
                box = tuple(sorted((f"{name}_box", partner)))
                if box in touching and tuple(sorted((name, partner))) not in touching:
                    out.add(name)
    return out


def peak_slots(kinds: dict[str, str], contacts: list[tuple[float, set]], swaps: dict) -> int | None:
    """The most contact slots in use at once in a sampled configuration that only touches
    (deepest penetration under `TOUCHING_DEPTH`): a servo stops a robot that meets itself
    there, so deeper configurations are never reached. None when no sample only touches."""
    touching = [c for depth, c in contacts if depth <= TOUCHING_DEPTH]
    if not touching:
        return None
    return max(sum(pair_slots(kinds, *p, swaps) for p in c) for c in touching)


# --- the floor: what a floating base stands on ------------------------------------------


def _cores(geom: dict) -> np.ndarray:
    """A round collider's core in its link frame: a sphere's centre, a capsule's end points."""
    centre = np.asarray(geom["xyz"], dtype=float)
    if geom["kind"] == "sphere":
        return centre[None]
    half = rpy_matrix(geom["rpy"]) @ np.array([0.0, 0.0, geom["length"] / 2])
    return np.stack([centre - half, centre + half])


def _inside_hull(points: np.ndarray, cloud: np.ndarray) -> bool:
    """Whether every point lies in the convex hull of `cloud` (a linear feasibility test,
    exact for flat and collinear clouds too)."""
    from scipy.optimize import linprog

    if not len(cloud):
        return False
    a_eq = np.vstack([cloud.T, np.ones(len(cloud))])
    for point in points:
        b_eq = np.append(point, 1.0)
        result = linprog(np.zeros(len(cloud)), A_eq=a_eq, b_eq=b_eq, bounds=(0, None))
        if result.status != 0:
            return False
    return True


def _prune_shadowed(candidates: list[dict]) -> list[dict]:
    """Drop round colliders whose core lies in the hull of the cores of the same link's other
    kept round colliders of at least their radius: against a plane those reach as deep."""
    kept = list(candidates)
    for geom in candidates:
        if geom["kind"] not in ("sphere", "capsule"):
            continue
        others = [
            g
            for g in kept
            if g is not geom
            and g["link"] == geom["link"]
            and g["kind"] in ("sphere", "capsule")
            and g["radius"] >= geom["radius"] - 1e-12
        ]
        cloud = np.concatenate([_cores(g) for g in others]) if others else np.zeros((0, 3))
        if _inside_hull(_cores(geom), cloud):
            kept.remove(geom)
    return kept


def standing_colliders(robot: Robot, geoms: list[dict]) -> set[str]:
    """Colliders within `STANDING_MARGIN` of the floor at home (a floating base at its spec
    origin, which the importer and the seeds put on the floor)."""
    import mujoco

    xml = scratch_xml(robot, geoms, never_collided(robot), floor=STANDING_MARGIN)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    names = [j for j, _, _ in sampled_joints(robot)]
    adr = np.array([model.jnt_qposadr[model.joint(n).id] for n in names], dtype=int)
    values = dict(robot.poses).get("home")
    movable = [j.name for j in robot.movable_joints]
    home = dict(zip(movable, values, strict=True)) if values else {}
    data.qpos[adr] = [home.get(n, 0.0) for n in names]
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    floor = model.geom("floor").id
    return {
        model.geom(int(b if a == floor else a)).name
        for a, b in data.contact.geom[: data.ncon]
        if floor in (a, b)
    }


def floor_colliders(geoms: list[dict]) -> list[str]:
    """Names of the colliders a floating base may meet the floor with: every collider, less
    the shadowed ones. A robot may rest on more than its feet (a quadruped lying on its hips
    at home), and the GPU scene must stand, fall and lie as the main MJCF does."""
    return sorted(g["name"] for g in _prune_shadowed(list(geoms)))


# --- the plan ---------------------------------------------------------------------------


def pair_slots(kinds: dict[str, str], a: str, b: str, swaps: dict | None = None) -> int:
    """MJX contact slots of one pair of colliders (`MJX_CONTACTS`); `floor` is the plane, and
    a cylinder in `swaps` with this partner is its stand-in box."""
    swaps = swaps or {}
    types = [
        "plane" if n == FLOOR else "box" if other in swaps.get(n, ()) else mujoco_type(kinds[n])
        for n, other in ((a, b), (b, a))
    ]
    return MJX_CONTACTS[tuple(sorted(types, key=TYPE_ORDER.index))]  # type: ignore[index]


def constraint_rows(robot: Robot, contacts: int) -> int:
    """An upper bound on constraint rows per world: every contact (condim 3, pyramidal), every
    joint limit, every joint with friction loss, every mimic equality, six per loop weld."""
    limited = sum(1 for j in robot.movable_joints if j.lower is not None and j.type != "continuous")
    friction = sum(1 for j in robot.movable_joints if j.friction)
    mimics = sum(1 for j in robot.joints if j.mimic is not None)
    return ROWS_PER_CONTACT * contacts + limited + friction + mimics + 6 * len(robot.loops)


def _colliders_for(robot: Robot, geoms: list[dict], pairs: list, floating: bool) -> dict:
    """Stand-in boxes and hull caps on `geoms` (in place); the cylinders' swaps."""
    standing = standing_colliders(robot, geoms) if floating else set()
    kinds = {g["name"]: g["kind"] for g in geoms}
    swaps = stand_ins(kinds, pairs)
    for geom in geoms:
        if geom["name"] in swaps:
            geom["box_for"] = swaps[geom["name"]]
            geom["box_half"] = geom["radius"]
        cap = STANDING_HULL_VERTICES if geom["name"] in standing else MAX_HULL_VERTICES
        if geom["kind"] == "piece" and len(piece_vertices(robot, geom)) > cap:
            geom["maxhullvert"] = cap
    inscribed = inscribed_stand_ins(robot, geoms, swaps) if swaps else set()
    for geom in geoms:
        if geom["name"] in inscribed:
            geom["box_half"] = geom["radius"] / math.sqrt(2)
    return swaps


def _draws_block(cull: dict) -> dict | None:
    """robot.json's statement of how far `max_geom_pairs` holds (None: no cull)."""
    if cull["k"] is None:
        return None
    bound = round(3.0 / RUN, 6)
    return {
        "run": RUN,
        "drawn": cull["drawn"],
        "sampled_k": cull["sampled"],
        "miss_below": bound,
        "confidence": CONFIDENCE,
    }


def plan_gpu_scene(robot: Robot) -> dict:
    """The GPU scene's plan: colliders, contact pairs, floor pairs and the contact budget.

    Slots per world are capped (MJX's `max_contact_points`, the deepest kept) at the floor
    pairs all at once (standing) plus twice the most slots self-contact needs at once in a
    sampled configuration that only touches (`peak_slots`)."""
    geoms = [g for link in robot.links for g in colliders(link)]
    q = configurations(robot, robot.seed)
    # the named poses too: a pair in contact where the servos hold the robot must collide
    named = _named_rows(robot)
    contacts = sampled_contacts(robot, geoms, np.vstack([named, q]))
    pairs = sorted([a, b] for a, b in set().union(*(c for _, c in contacts)))
    floating = robot.floating_joint is not None
    floor = floor_colliders(geoms) if floating else []
    held = set().union(*(c for _, c in sampled_contacts(robot, geoms, named)))
    pairs, cut = capped_pairs(pairs, held, contacts, MAX_PAIRS - len(floor))
    kept = {tuple(p) for p in pairs}
    contacts = [(d, c & kept) for d, c in contacts if c & kept]
    swaps = _colliders_for(robot, geoms, pairs, floating)
    kinds = {g["name"]: g["kind"] for g in geoms}
    boxes = [stand_in_box(g, g["box_half"]) for g in geoms if g["name"] in swaps]
    cull = max_geom_pairs(
        robot,
        geoms + boxes,
        mjx_pairs(pairs, kinds, swaps),
        np.vstack([named, q]),
        TOUCHING_DEPTH,
    )
    standing = sum(pair_slots(kinds, FLOOR, g) for g in floor)
    every = standing + sum(pair_slots(kinds, a, b, swaps) for a, b in pairs)
    peak = peak_slots(kinds, contacts, swaps)
    budget = every if peak is None else min(every, standing + 2 * peak)
    block = {
        "colliders": geoms,
        "pairs": pairs,
        "floor_pairs": floor,
        "pair_slots": every,
        "touching_peak": peak,
        "contact_slots": budget,
        "max_geom_pairs": cull["k"],
        "broadphase_rank": cull["rank"],
        "broadphase_draws": _draws_block(cull),
        "nconmax": max(budget, 1),
        "njmax": max(constraint_rows(robot, budget), 1),
        "method": METHOD,
        "seed": robot.seed,
        "samples": len(q),
    }
    (block["iterations"], block["ls_iterations"]), hold = fewest_iterations(robot, block)
    block["hold"] = round(hold, 6)  # m; micrometres: the figure, not the platform's last bits
    notes = [cut] if cut else []
    if budget > SLOT_TARGET:
        notes.append(
            f"the GPU scene needs {budget} contact slots per world, over the {SLOT_TARGET} "
            "simkit aims for: the source's collision geometry touches in that many places"
        )
    if notes:
        block["note"] = "; ".join(notes)
    return block


def derive_gpu_scene(robot: Robot) -> Robot:
    """`products.gpu_scene`: the plan (`plan_gpu_scene`), or one line saying why the kit has
    no GPU scene where MuJoCo cannot compile the colliders (a GPU scene never fails a build)."""
    try:
        block = plan_gpu_scene(robot)
    except ValueError as exc:  # MuJoCo's compiler: e.g. a collision piece it cannot hull
        block = no_scene(f"MuJoCo cannot compile its colliders ({str(exc).splitlines()[0]})")
    if block.get("hold", 0.0) > HOLD_TOLERANCE:
        block = no_scene(
            f"held at its named poses with the GPU scene's pairs it ends {block['hold'] * 1e3:.1f} "
            f"mm from where every contact puts it, even at solver iterations {block['iterations']}"
            f" / {block['ls_iterations']} (the gpu_scene check allows {HOLD_TOLERANCE * 1e3:g} mm)"
        )
    seeds = {**robot.products.seeds, "gpu_scene": robot.seed}
    return replace(robot, products=replace(robot.products, gpu_scene=block, seeds=seeds))
