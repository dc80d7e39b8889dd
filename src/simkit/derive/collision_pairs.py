"""Collision pairs for the SRDF: adjacent links, and links that never touch.

Follows what MoveIt Setup Assistant does (moveit_setup_srdf_plugins, compute_default_collisions):
links joined by a joint are "Adjacent" (a link without collision geometry joins its neighbours
to each other), and a pair that is never in contact over many random configurations within
the joint limits is "Never". The kit page ("Simulation parameters") keeps MuJoCo's own rule
(adjacent pairs only); this list is only for planners.

Sampling runs MuJoCo's collision detection on a model built from each link's collision
geometry as the URDF gives it: the spec's primitives, else the convex pieces, else the visual
solid (whose convex hull MuJoCo collides, which can only add contacts, never hide one).
The configurations are drawn from a seeded generator and can be regenerated from robot.json
(`sample_unit` with the recorded seed and count, scaled to each joint's limits).
"""

from __future__ import annotations

import itertools
import math
import xml.etree.ElementTree as ET
from dataclasses import replace

import numpy as np

from simkit.model.kinematics import contracted_pairs, jointed_pairs, quat_wxyz, rpy_matrix
from simkit.model.robot import Joint, Link, Robot, Shape

SAMPLES = 10_000
#: configurations (the first of the sampled ones) a pair's contact is counted in for "Always"
ALWAYS_SAMPLES = 1000
#: share of those a pair must be in contact in to be "Always" (MoveIt Setup Assistant's
#: "min. collisions for always-colliding pairs", 95 % by default)
ALWAYS_FRACTION = 0.95
#: m: geometry closer than this touches (faces that meet exactly, up to rounding)
TOUCH = 1e-6
SAMPLED_TYPES = ("revolute", "continuous", "prismatic")
METHOD = (
    "MoveIt Setup Assistant's rule: 'Adjacent' = links joined by a joint (links without "
    "collision geometry join their neighbours); 'Never' = no contact between the links' "
    "collision geometry (MuJoCo collision detection, margin 0) in any of `samples` "
    "configurations q = lower + u * (upper - lower), u = numpy.random.default_rng(seed)"
    ".random((samples, len(joints))), joints in robot.json order (continuous joints over "
    "-pi..pi)"
)


def has_geometry(link: Link) -> bool:
    return bool(link.collision_primitives or link.collision or link.solid is not None)


def adjacent_pairs(robot: Robot) -> list[tuple[str, str]]:
    """Pairs of links with collision geometry joined by a joint or a loop closure, or by a
    chain of links and frames without geometry (MoveIt Setup Assistant's connection graph),
    sorted."""
    solid = {link.name for link in robot.links if has_geometry(link)}
    joined = [(j.parent, j.child) for j in robot.joints]
    joined += [(lp.link1, lp.link2) for lp in robot.loops]  # a loop closure joins them too
    return sorted(contracted_pairs(joined, solid))


def sampled_joints(robot: Robot) -> list[tuple[str, float, float]]:
    """(name, lower, upper) of the joints the sampler moves, in tree (robot.json) order."""
    out = []
    for joint in robot.joints:
        if joint.type not in SAMPLED_TYPES:
            continue
        if joint.type == "continuous" or joint.lower is None or joint.upper is None:
            out.append((joint.name, -math.pi, math.pi))
        else:
            out.append((joint.name, joint.lower, joint.upper))
    return out


def sample_unit(seed: int, samples: int, joints: int) -> np.ndarray:
    """The unit-cube draws behind the sampled configurations (samples x joints)."""
    return np.random.default_rng(seed).random((samples, joints))


def configurations(robot: Robot, seed: int, samples: int = SAMPLES) -> np.ndarray:
    """Random joint positions within the limits (samples x sampled joints)."""
    limits = np.array([(lo, hi) for _, lo, hi in sampled_joints(robot)], dtype=float)
    unit = sample_unit(seed, samples, len(limits))
    if not len(limits):
        return unit
    return limits[:, 0] + unit * (limits[:, 1] - limits[:, 0])


def _text(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def _shape_geom(body: ET.Element, shape: Shape) -> None:
    attrs = {"pos": _text(shape.xyz), "quat": _text(quat_wxyz(rpy_matrix(shape.rpy)))}
    if shape.kind == "box":
        attrs.update(type="box", size=_text(np.asarray(shape.size) / 2))
    elif shape.kind == "sphere":
        attrs.update(type="sphere", size=_text([shape.radius]))
    else:  # cylinder, capsule: radius and half-length along local z
        attrs.update(type=shape.kind, size=_text([shape.radius, shape.length / 2]))
    ET.SubElement(body, "geom", attrs)


def _mesh_geom(asset: ET.Element, body: ET.Element, name: str, vertices: np.ndarray) -> None:
    # Vertices only: MuJoCo collides the convex hull of a mesh.
    ET.SubElement(asset, "mesh", name=name, vertex=_text(vertices))
    ET.SubElement(body, "geom", type="mesh", mesh=name)


def scratch_body(parent: ET.Element, joint: Joint) -> ET.Element:
    """A scratch model's body for `joint`'s child at the joint origin, unit mass, with a hinge
    or slide; a fixed or floating joint gets a slide that is never moved (so MuJoCo welds no
    two bodies together)."""
    quat = quat_wxyz(rpy_matrix(joint.rpy))
    body = ET.SubElement(parent, "body", name=joint.child, pos=_text(joint.xyz), quat=_text(quat))
    ET.SubElement(body, "inertial", pos="0 0 0", mass="1", diaginertia="1 1 1")
    if joint.type in ("revolute", "continuous"):
        ET.SubElement(body, "joint", name=joint.name, type="hinge", axis=_text(joint.axis))
    elif joint.type == "prismatic":
        ET.SubElement(body, "joint", name=joint.name, type="slide", axis=_text(joint.axis))
    else:
        ET.SubElement(body, "joint", name=f"{joint.name}_locked", type="slide")
    return body


def collision_model_xml(robot: Robot, skip: list[tuple[str, str]] = (), margin: float = 0.0) -> str:
    """MJCF of the links' collision geometry, every link pair able to touch except `skip`:
    every body has a degree of freedom (fixed joints get a locked slide) so MuJoCo welds none
    together, and the parent filter is off. `margin` (m, per geom): contacts closer than
    twice it count."""
    root = ET.Element("mujoco", model=f"{robot.name}_collision_pairs")
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false")
    option = ET.SubElement(root, "option")
    ET.SubElement(option, "flag", filterparent="disable", gravity="disable")
    margin_text = repr(float(margin)) if margin else "0"
    ET.SubElement(
        ET.SubElement(root, "default"), "geom", contype="1", conaffinity="1", margin=margin_text
    )
    asset = ET.SubElement(root, "asset")
    bodies = {robot.root: ET.SubElement(root, "worldbody")}
    for joint in robot.joints:
        link = robot.link(joint.child)
        body = bodies[link.name] = scratch_body(bodies[joint.parent], joint)
        if link.collision_primitives:
            for shape in link.collision_primitives:
                _shape_geom(body, shape)
        elif link.collision:
            for i, piece in enumerate(link.collision):
                _mesh_geom(asset, body, f"{link.name}_{i:02d}", piece.vertices)
        elif link.solid is not None:
            _mesh_geom(asset, body, link.name, link.solid.vertices)
    contact = ET.SubElement(root, "contact")
    for a, b in skip:
        ET.SubElement(contact, "exclude", body1=a, body2=b)
    return ET.tostring(root, encoding="unicode")


def first_contacts(
    robot: Robot,
    q: np.ndarray,
    skip: list[tuple[str, str]] = (),
) -> dict[tuple[str, str], int | None]:
    """For each link pair with geometry (except `skip`), the index of the first configuration
    (row of `q`) in which its collision geometry is in contact, or None if it never is.

    A pair is only tested until its first contact: the model is rebuilt, excluding the pairs
    found so far, after batches of doubling size. That gives the same answer as testing every
    pair in every configuration, in a fraction of the time (the costly pairs are the close
    ones, and they touch early)."""
    import mujoco

    solid = sorted(link.name for link in robot.links if has_geometry(link))
    first: dict[tuple[str, str], int | None] = {
        pair: None for pair in itertools.combinations(solid, 2) if pair not in set(skip)
    }
    names = [j for j, _, _ in sampled_joints(robot)]
    start, batch = 0, 64
    while start < len(q) and any(v is None for v in first.values()):
        found = [pair for pair, v in first.items() if v is not None]
        model = mujoco.MjModel.from_xml_string(collision_model_xml(robot, [*skip, *found]))
        data = mujoco.MjData(model)
        adr = np.array([model.jnt_qposadr[model.joint(n).id] for n in names], dtype=int)
        body_name = [model.body(i).name for i in range(model.nbody)]
        for index in range(start, min(start + batch, len(q))):
            data.qpos[adr] = q[index]
            mujoco.mj_kinematics(model, data)
            mujoco.mj_collision(model, data)
            for g1, g2 in data.contact.geom[: data.ncon]:
                a, b = body_name[model.geom_bodyid[g1]], body_name[model.geom_bodyid[g2]]
                pair = (a, b) if a < b else (b, a)
                if first[pair] is None:
                    first[pair] = index
        start += batch
        batch *= 2
    return first


def welded_pairs(robot: Robot) -> set[tuple[str, str]]:
    """Link pairs whose contacts MuJoCo filters in the kit's MJCF by itself: bodies welded
    together by fixed joints, and a welded group with its parent group (the parent filter),
    except where the parent group is welded to the world: MuJoCo's parent filter skips the
    world body (a robot's head turning inside spheres fixed to its base, which do collide)."""
    parent = {j.child: j for j in robot.joints}

    def weld(link: str) -> str:
        while link in parent and parent[link].type == "fixed":
            link = parent[link].parent
        return link

    groups = {link.name: weld(link.name) for link in robot.links}
    world = weld(robot.root)  # the root's group: welded to MuJoCo's world body
    up = {g: weld(parent[g].parent) for g in set(groups.values()) if g in parent}
    up = {g: p for g, p in up.items() if p != world}
    out = set()
    for a, b in itertools.combinations(sorted(groups), 2):
        ga, gb = groups[a], groups[b]
        if ga == gb or up.get(ga) == gb or up.get(gb) == ga:
            out.add((a, b))
    return out


def _kit_collides(link: Link) -> bool:
    """Whether the kit's MJCF gives the link collision geoms (emit/mjcf.py: a link whose
    collision is `primitives` and lists none has none; this model would collide its solid)."""
    if link.collision_primitives:
        return True
    has_mesh = bool(link.collision) or link.solid is not None
    return link.collision_method != "primitives" and has_mesh


def always_pairs(
    robot: Robot, q: np.ndarray, declared: list[tuple[str, str]] = ()
) -> list[tuple[str, str]]:
    """Link pairs the kit's MJCF would let collide whose collision geometry is in contact (or
    within `TOUCH`, numerically touching) in at least `ALWAYS_FRACTION` of the configurations
    of `q` (MoveIt Setup Assistant's "Always", its min_collision_fraction): a URDF's
    collision shapes that overlap wherever the joints are (a humanoid's hip-yaw and thigh
    hulls, a fingertip inside the hand's safety box but in one pose of a thousand, finger
    blocks sliding face on face) can never, or almost never, be separated, so their
    contact is an artefact of the geometry, and the kit excludes it. `declared` pairs are
    excluded already (the spec's `contact_excludes`) and never tested."""
    import mujoco

    if not len(q):
        return []
    q = follow_mimics(robot, q)
    need = math.ceil(ALWAYS_FRACTION * len(q) - 1e-9)
    skip = welded_pairs(robot) | {tuple(sorted(p)) for p in jointed_pairs(robot)}
    skip |= {tuple(sorted(p)) for p in declared}
    kit = {link.name for link in robot.links if _kit_collides(link)}
    solid = sorted(link.name for link in robot.links if has_geometry(link))
    names = [j for j, _, _ in sampled_joints(robot)]
    candidates = {p for p in itertools.combinations(solid, 2) if p not in skip and set(p) <= kit}
    count = dict.fromkeys(candidates, 0)
    body_name, model, data, adr = [], None, None, None
    for index, row in enumerate(q):
        # a pair that cannot reach `need` any more is dropped (the model is rebuilt without
        # the dropped pairs after doubling batches of rows)
        candidates = {p for p in candidates if count[p] + len(q) - index >= need}
        if not candidates:
            break
        if model is None or (index & (index - 1) == 0 and index >= 32):
            others = [p for p in itertools.combinations(solid, 2) if p not in candidates]
            model = mujoco.MjModel.from_xml_string(collision_model_xml(robot, others, TOUCH / 2))
            data = mujoco.MjData(model)
            adr = np.array([model.jnt_qposadr[model.joint(n).id] for n in names], dtype=int)
            body_name = [model.body(i).name for i in range(model.nbody)]
        data.qpos[adr] = row
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        touching = set()
        for g1, g2 in data.contact.geom[: data.ncon]:
            a, b = body_name[model.geom_bodyid[g1]], body_name[model.geom_bodyid[g2]]
            touching.add((a, b) if a < b else (b, a))
        for p in touching & candidates:
            count[p] += 1
    return sorted(p for p in candidates if count[p] >= need)


def loop_pairs(
    robot: Robot, adjacent: list[tuple[str, str]], known: set[tuple[str, str]]
) -> list[tuple[str, str]]:
    """Pairs around a loop closure (spec `loops`) in contact at home: one link a welded link
    or its neighbour (`adjacent`), the other the other welded link or its neighbour. The
    sampler moves the joints a weld locks, so it cannot see them; a pair that touches where
    the loop holds the robot is excluded, as MoveIt's "Default" pairs are. `known` pairs
    (excluded already) are not tested."""
    near: dict[str, set[str]] = {}
    for a, b in adjacent:
        near.setdefault(a, set()).add(b)
        near.setdefault(b, set()).add(a)
    candidates = set()
    for loop in robot.loops:
        ends = [{name, *near.get(name, ())} for name in (loop.link1, loop.link2)]
        candidates |= {tuple(sorted((x, y))) for x in ends[0] for y in ends[1] if x != y}
    candidates -= set(adjacent) | {tuple(sorted(p)) for p in known}
    kit = {link.name for link in robot.links if _kit_collides(link)}
    candidates = {p for p in candidates if set(p) <= kit}
    if not candidates:
        return []
    values = dict(robot.poses).get("home") or [0.0] * len(robot.movable_joints)
    home = dict(zip([j.name for j in robot.movable_joints], values, strict=True))
    row = np.array([[home.get(name, 0.0) for name, _, _ in sampled_joints(robot)]])
    solid = sorted(link.name for link in robot.links if has_geometry(link))
    others = [p for p in itertools.combinations(solid, 2) if p not in candidates]
    first = first_contacts(robot, follow_mimics(robot, row), others)
    return sorted(p for p, index in first.items() if index is not None)


def follow_mimics(robot: Robot, q: np.ndarray) -> np.ndarray:
    """`q` (sampled_joints order) with each mimic joint at its leader's value times the
    multiplier plus the offset, as the kit's MJCF equality holds it."""
    names = [name for name, _, _ in sampled_joints(robot)]
    index = {name: i for i, name in enumerate(names)}
    q = np.array(q, dtype=float)
    for joint in robot.joints:
        if joint.mimic is not None and joint.name in index and joint.mimic[0] in index:
            leader, multiplier, offset = joint.mimic
            q[:, index[joint.name]] = multiplier * q[:, index[leader]] + offset
    return q


def derive_collision_pairs(robot: Robot, samples: int = SAMPLES) -> Robot:
    """Adjacent, always-in-contact and never-in-contact link pairs
    (`products.collision_pairs`: the SRDF, the MJCF and USD excludes and robot.json
    `collision_pairs`); the seed is the spec's. `always` is written only when not empty,
    and so is `declared`, the pairs the spec's `contact_excludes` declares (never sampled:
    the source lets them overlap)."""
    seed = robot.seed
    adjacent = adjacent_pairs(robot)
    declared = list(robot.contact_excludes)
    q = configurations(robot, seed, samples)
    first = first_contacts(robot, q, [*adjacent, *declared])
    always = always_pairs(robot, q[:ALWAYS_SAMPLES], declared)
    block = {
        "method": METHOD,
        "seed": seed,
        "samples": samples,
        "joints": [name for name, _, _ in sampled_joints(robot)],
        "adjacent": [list(p) for p in adjacent],
        "never": [list(p) for p, index in first.items() if index is None],
        "first_contact": {f"{a} {b}": i for (a, b), i in first.items() if i is not None},
    }
    if always:
        block["always"] = [list(p) for p in always]
        block["always_rule"] = {
            "samples": ALWAYS_SAMPLES,
            "fraction": ALWAYS_FRACTION,
            "touch": TOUCH,
        }
    if declared:
        block["declared"] = [list(p) for p in declared]
    closing = loop_pairs(robot, adjacent, {*declared, *always})
    if closing:  # only where the spec closes a loop: other kits are unchanged
        block["loop"] = [list(p) for p in closing]
    seeds = {**robot.products.seeds, "collision_pairs": seed}
    return replace(robot, products=replace(robot.products, collision_pairs=block, seeds=seeds))
