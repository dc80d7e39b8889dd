"""Mass properties a URDF leaves out, estimated from the links' own solids, and the estimated
rotor inertia (armature) of each joint, bounded by what the joint moves.

A URDF without `<inertial>` elements would otherwise become a robot of 1 g links (a 7 g
industrial arm that the kit's servos fling about). A massless link with a visual solid gets
the mass of that solid at `DENSITY` (aluminium, `--density` sets another): the volume of each
visual piece (the closed mesh the importer writes, or the convex hull it writes for an open
mesh; primitives exactly), its centre of mass and its inertia, summed about the link's CoM.
Which links: every link with a solid when the URDF gives no link a mass; otherwise those on a
movable joint (a massless link on a fixed joint is the author's frame or housing, merged
into its parent). Marked `estimated`, reported per link.

Armature: a URDF carries no rotor inertia, but simkit's servo (kp = effort per 0.01 rad)
needs inertia to stay stable at the kit's 2 ms step. The estimate is `ARMATURE_PER_EFFORT`
x effort (a geared motor's reflected rotor inertia), but at most `ARMATURE_SHARE` x the
inertia about the joint's axis of everything it moves at home (mass for a prismatic joint),
so the rotor never swamps the joint's own inertia. Where that bound holds it lower, the
servo's stiffness is lowered with it to keep its frequency at `SERVO_OMEGA` (the frequency
the old rule bounded it to): kp = SERVO_OMEGA^2 x (axis inertia + armature), marked
estimated. Each joint's value is reported with the rule that gave it.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

#: kg/m^3 of an estimated solid: aluminium (`--density` sets another)
DENSITY = 2700.0
#: kg m^2 per N m of effort (kg per N for prismatic): a geared motor's reflected rotor inertia
ARMATURE_PER_EFFORT = 1.0e-3
#: the armature is at most this share of the axis inertia of what the joint moves
ARMATURE_SHARE = 3.0
#: rad/s: the servo frequency a bounded armature keeps (sqrt(100 / 1e-3): the frequency
#: ARMATURE_PER_EFFORT gives simkit's servo; 0.63 rad per 2 ms step)
SERVO_OMEGA = math.sqrt(1.0e5)


def _box_inertia(size, mass: float) -> np.ndarray:
    a, b, c = (float(s) for s in size)
    return mass / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])


def _cylinder_inertia(radius: float, length: float, mass: float) -> np.ndarray:
    side = mass * (3 * radius * radius + length * length) / 12.0
    return np.diag([side, side, mass * radius * radius / 2.0])


def _piece(shape: dict, stage: Path) -> tuple[float, np.ndarray, np.ndarray, str] | None:
    """(volume m^3, centroid m, inertia at unit density about the centroid kg m^2, what) of
    one spec primitive in its own frame; None for a shape without volume."""
    kind = shape["shape"]
    if kind == "mesh":
        import trimesh

        from simkit.kitio.stl import from_stl

        mesh = from_stl((stage / shape["file"]).read_bytes())
        solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)
        what = "mesh"
        if not solid.is_watertight or solid.volume <= 0:
            solid, what = solid.convex_hull, "convex hull"
        if solid.volume <= 0:
            return None
        return float(solid.volume), np.asarray(solid.center_mass), solid.moment_inertia, what
    if kind == "box":
        volume = float(np.prod(shape["size"]))
        return volume, np.zeros(3), _box_inertia(shape["size"], volume), "box"
    if kind == "sphere":
        r = float(shape["radius"])
        volume = 4.0 / 3.0 * math.pi * r**3
        return volume, np.zeros(3), np.eye(3) * 0.4 * volume * r * r, "sphere"
    r, length = float(shape["radius"]), float(shape["length"])
    if kind == "cone":  # a frustum: its volume, the inertia of a cylinder of the mean radius
        top = float(shape.get("radius_top") or 0.0)
        volume = math.pi * length / 3.0 * (r * r + r * top + top * top)
        return volume, np.zeros(3), _cylinder_inertia((r + top) / 2, length, volume), kind
    volume = math.pi * r * r * length
    if kind == "capsule":  # the end spheres too; inertia of the bounding cylinder
        volume += 4.0 / 3.0 * math.pi * r**3
        return volume, np.zeros(3), _cylinder_inertia(r, length + 2 * r, volume), kind
    return volume, np.zeros(3), _cylinder_inertia(r, length, volume), kind


def solid_mass(shapes: list[dict], stage: Path, density: float):
    """(mass kg, com m, inertia about the com kg m^2 (3x3, link axes), volume m^3, what
    the volumes came from) of a link's solid at `density`; None when it has no volume."""
    from simkit.model.kinematics import rpy_matrix

    pieces = []
    for shape in shapes:
        got = _piece(shape, stage)
        if got is None:
            continue
        volume, centroid, inertia, what = got
        rotation = rpy_matrix(shape.get("rpy", (0.0, 0.0, 0.0)))
        centre = rotation @ centroid + np.asarray(shape.get("xyz", (0.0, 0.0, 0.0)))
        pieces.append((volume, centre, rotation @ inertia @ rotation.T, what))
    volume = sum(p[0] for p in pieces)
    if volume <= 0:
        return None
    mass = density * volume
    com = sum(p[0] * p[1] for p in pieces) / volume
    tensor = np.zeros((3, 3))
    for v, centre, inertia, _what in pieces:
        d = centre - com
        tensor += density * (inertia + v * (d @ d * np.eye(3) - np.outer(d, d)))
    whats = ", ".join(sorted({p[3] for p in pieces}))
    return mass, com, tensor, volume, whats


def axis_inertias(robot, q) -> dict[str, float]:
    """Per movable joint: kg m^2 about a revolute joint's axis (kg for a prismatic one) of
    everything it moves at `q` (dynamics.axis_inertia's measure). Each link's mass, first and
    second moments (world frame, at the origin) are summed up the tree once, children before
    parents, and shifted to each joint's axis: linear in the links, not quadratic."""
    from simkit.model.kinematics import forward

    poses = forward(robot, q)
    sums: dict[str, list] = {}  # link -> [mass, sum m p, sum m p p^T, sum R I R^T]
    for link in robot.links:
        part = [0.0, np.zeros(3), np.zeros((3, 3)), np.zeros((3, 3))]
        if link.inertial is not None and link.name in poses:
            rot, mass = poses[link.name][:3, :3], link.inertial.mass
            p = rot @ np.asarray(link.inertial.com) + poses[link.name][:3, 3]
            part = [mass, mass * p, mass * np.outer(p, p), rot @ link.inertial.tensor() @ rot.T]
        sums[link.name] = part
    for joint in reversed(robot.joints):  # joints list parents first: children summed first
        if joint.parent in sums and joint.child in sums:
            both = zip(sums[joint.parent], sums[joint.child], strict=True)
            sums[joint.parent] = [a + b for a, b in both]
    out = {}
    for joint in robot.movable_joints:
        mass, first, second, spin = sums[joint.child]
        if joint.type == "prismatic":
            out[joint.name] = float(mass)
            continue
        axis = poses[joint.child][:3, :3] @ np.asarray(joint.axis)
        o = poses[joint.child][:3, 3]
        r2 = np.trace(second) - 2 * o @ first + mass * (o @ o)  # sum m |p - o|^2
        along = axis @ second @ axis - 2 * (axis @ o) * (axis @ first) + mass * (axis @ o) ** 2
        out[joint.name] = float(axis @ spin @ axis + r2 - along)
    return out


def armature(draft) -> None:
    """Each driven joint's estimated armature (module doc), and the servo stiffness that
    keeps a bounded one stable; one report line per joint."""
    robot = draft.robot()
    home = dict(robot.poses).get("home")
    source = draft.source
    inertias = axis_inertias(robot, home)
    named: dict = {}  # the first URDF joint of each name, as `find` gives it
    for element in source.root.findall("joint"):
        named.setdefault(element.get("name"), element)
    for spec in draft.movable():
        if "mimic" in spec or "armature" in spec:
            continue  # a follower has no servo of its own
        effort = float(spec["effort_peak"])
        own = inertias[spec["name"]]
        by_effort = float(f"{ARMATURE_PER_EFFORT * effort:.3g}")
        bound = float(f"{ARMATURE_SHARE * own:.3g}")
        element = named.get(spec["name"])
        limit = None if element is None else element.find("limit")
        where = limit if limit is not None else element if element is not None else source.root
        unit = "kg" if spec["type"] == "prismatic" else "kg m^2"
        if by_effort <= bound or bound <= 0.0:
            spec["armature"] = by_effort
            why = (
                f"no armature in a URDF: {by_effort:g} {unit} ({ARMATURE_PER_EFFORT:g} x effort, "
                f"a geared motor's reflected rotor inertia; within {ARMATURE_SHARE:g} x the "
                f"{own:.3g} {unit} it moves; keeps the servo stable on light links)"
            )
            spec["estimated"] = [*spec.get("estimated", []), "armature"]
        else:
            spec["armature"] = bound
            kp = float(f"{SERVO_OMEGA**2 * (own + bound):.3g}")
            spec["kp"] = kp
            why = (
                f"no armature in a URDF: {bound:g} {unit}, {ARMATURE_SHARE:g} x the {own:.3g} "
                f"{unit} the joint moves at home ({ARMATURE_PER_EFFORT:g} x effort, "
                f"{by_effort:g}, would swamp it); servo kp {kp:g} (not effort / 0.01 rad) so "
                f"that it stays at {SERVO_OMEGA:.0f} rad/s, stable at the kit's 2 ms step"
            )
            spec["estimated"] = [*spec.get("estimated", []), "armature", "kp"]
        draft.report.assumed(source, where, why)
    draft.changed()
