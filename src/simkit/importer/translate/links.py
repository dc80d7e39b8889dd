"""A source model `Link` to a spec link: inertial, geometry, colour and collision choice."""

from __future__ import annotations

import math

import numpy as np

from simkit.importer.diagnostics import Report
from simkit.importer.read.model import Geometry, Link
from simkit.importer.read.source import Source
from simkit.importer.translate import inertia_limit, points
from simkit.importer.translate.geometry import shape_of
from simkit.importer.translate.masses import solid_mass
from simkit.importer.translate.meshes import MeshWriter
from simkit.model.kinematics import rpy_matrix
from simkit.spec.bounds import FIELD_BOUNDS
from simkit.spec.schema import InertiaSpec
from simkit.spec.validate import inertia_problem

#: kg and kg m^2 given to a link the URDF leaves massless (MuJoCo needs mass on moving bodies)
MASSLESS_MASS, MASSLESS_INERTIA = 0.001, 1.0e-7
#: kg: the smallest mass a spec accepts; a URDF's smaller one is raised to it
MIN_MASS = FIELD_BOUNDS["mass"][0]
#: kg/m^3 of the solid sphere whose inertia replaces a zero one
DENSITY = 1000.0


def has_mass(link: Link) -> bool:
    """True when the link's inertial gives a positive mass."""
    return link.massive


def has_geometry(link: Link) -> bool:
    """True when the link has a visual or a collision."""
    return link.drawn


def _rotated(tensor: np.ndarray, rpy) -> np.ndarray:
    rot = rpy_matrix(rpy)
    return rot @ tensor @ rot.T


def inertial(source: Source, link: Link, report: Report) -> dict:
    """mass, com, inertia (about the CoM, link axes) and the estimates and decision made."""
    element = link.inertial
    if element is None or not element.massive:
        report.estimated(
            source,
            link.at,
            f"no positive mass in the {source.noun}: {MASSLESS_MASS} kg, inertia "
            f"{MASSLESS_INERTIA} kg m^2",
        )
        i = MASSLESS_INERTIA
        return {
            "mass": MASSLESS_MASS,
            "com": [0.0, 0.0, 0.0],
            "inertia": {"ixx": i, "iyy": i, "izz": i},
            "estimated": ["mass", "com", "inertia"],
            "note": f"massless in the {source.noun}; a small mass keeps MuJoCo's moving bodies "
            "valid",
        }
    mass = element.mass
    xyz, rpy = element.origin.xyz, element.origin.rpy
    tag = element.inertia_at if element.inertia is not None else None
    ixx, iyy, izz, ixy, ixz, iyz = element.inertia or (0.0,) * 6
    tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    if any(rpy):
        tensor = _rotated(tensor, rpy)
    keys = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
    flat = (tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2])
    out: dict = {"mass": mass, "com": list(xyz)}
    if mass < MIN_MASS:  # a placeholder mass (1e-6 kg) is below what the spec accepts
        tensor, mass = tensor * (MIN_MASS / mass), MIN_MASS
        flat = (tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2])
        report.estimated(
            source,
            element.mass_at,
            f"mass {out['mass']:g} kg is too small to simulate: {MIN_MASS:g} kg, inertia "
            "scaled by the same factor (same radius of gyration)",
        )
        out.update(mass=mass, estimated=["mass", "inertia"])
    if np.trace(tensor) <= 1e-12 * max(mass, 1e-12):
        radius = (3 * mass / (4 * math.pi * DENSITY)) ** (1 / 3)
        moment = 0.4 * mass * radius * radius
        report.estimated(
            source,
            tag if tag is not None else element.at,
            f"zero inertia: a {DENSITY:g} kg/m^3 solid sphere of that mass ({moment:.3g} kg m^2)",
        )
        out["inertia"] = {"ixx": moment, "iyy": moment, "izz": moment}
        out["estimated"] = sorted({*out.get("estimated", []), "inertia"})
        return out
    out["inertia"] = {k: float(round(v, 15)) for k, v in zip(keys, flat, strict=True)}
    inertia_limit.nudge(source, tag, out, report)  # a flat plate MuJoCo would refuse
    problem = inertia_problem(InertiaSpec(**out["inertia"]))
    if problem:
        report.estimated(source, tag, f"{problem}: balanced (inertia_decision)")
        out["inertia_decision"] = {
            "action": "balance",
            "reason": f"the {source.noun}'s inertia is not physical ({problem}); imported as "
            "given, "
            "the kit carries the balanced tensor",
        }
    return out


def _colour(visual: Geometry, materials: dict[str, tuple]) -> tuple | None:
    """A visual's rgba (0..1): its material's own colour, else the named material's."""
    material = visual.material
    if material is None:
        return None
    if material.rgba is not None:
        return material.rgba
    return materials.get(material.name or "")


def link_spec(
    source: Source,
    link: Link,
    writer: MeshWriter,
    report: Report,
    materials: dict[str, tuple],
    colours: dict[tuple, str],
    hull_collision: bool = False,
    density: float | None = None,
    volume_mass: bool = True,
) -> dict:
    """The spec dict of one link. `colours` maps rgba -> material name (filled here).
    `density` (kg/m^3): a massless link gets the mass of its solid at it (masses.py).
    `volume_mass`: a link without a visual may take its mass from its collision geometry
    (False where other links have visuals: such a link's collision geometry is a safety
    volume around a body, such as a capsule about an arm link, not a body; issue 32)."""
    spec: dict = {"name": link.name}
    if has_mass(link) or density is None:
        spec.update(inertial(source, link, report))
    for child in link.unknown:
        report.dropped(source, child, f"not {source.a_noun} link element simkit keeps")
    visuals, rgba = [], None
    for visual in link.visuals:
        got = shape_of(source, visual, link, writer, report, "visual")
        if got is None:
            continue
        shape, info = got
        visuals.append(shape)
        if info is not None and info.repair == "hull":
            report.changed(
                source, visual.at, f"{shape['file']}: open mesh, its convex hull is used"
            )
        colour = _colour(visual, materials) or (info.rgba if info else None)
        if colour is not None and rgba is not None and tuple(map(float, colour)) != rgba:
            report.changed(  # a kit link is one solid with one material
                source,
                visual.at,
                f"colour {' '.join(f'{c:g}' for c in colour)}: the link's solid takes its "
                f"first visual's colour, {' '.join(f'{c:g}' for c in rgba)}",
            )
        if rgba is None and colour is not None:
            rgba = tuple(float(c) for c in colour)
    collisions, sources = [], []
    for collision in link.collisions:
        got = shape_of(source, collision, link, writer, report, "collision")
        if got is not None:
            collisions.append(got[0])
            sources.append(collision.piece_of or f"#{len(sources)}")
    if points.grown(source, link.at, collisions, report):
        spec["estimated"] = [*spec.get("estimated", []), "collision_primitives"]
    solid = visuals
    weighed = "mass" not in spec and (bool(visuals) or volume_mass)
    if not visuals and collisions:
        solid = collisions
        report.changed(
            source,
            link.at,
            "no visual: the collision geometry is the visual solid"
            + ("" if weighed or "mass" in spec else " (a safety volume: no mass from it)"),
        )
    used = {s["file"] for s in solid if s["shape"] == "mesh"}
    if any(i.file in used and i.repair == "hull" for i in writer.done.values()):
        spec["estimated"] = [*spec.get("estimated", []), "solid"]
    if "mass" not in spec:  # massless: its mass from its solid, or the placeholder speck
        spec.update(_from_solid(source, link, report, solid if weighed else [], writer, density))
    if solid:
        spec["solid"] = solid
    if rgba is not None:
        colours.setdefault(rgba, f"colour_{len(colours)}")
        spec["material"] = colours[rgba]
    chosen = _collision(collisions, sources)
    if hull_collision and chosen["collision"] in ("given", "auto"):
        chosen = {"collision": "mesh"}
        report.changed(source, link.at, "collision meshes: the visual solid's convex hull (--hull)")
    spec.update(chosen)
    return spec


def _from_solid(
    source: Source, link: Link, report: Report, solid, writer: MeshWriter, density
) -> dict:
    """A massless link's mass, CoM and inertia: its visual solid's at `density` (kg/m^3),
    estimated and reported; the placeholder speck (`inertial`) where it has no volume."""
    found = solid_mass(solid, writer.out_dir, density) if solid else None
    if found is None or found[0] < MIN_MASS:
        return inertial(source, link, report)
    mass, com, tensor, volume, what = found
    report.estimated(
        source,
        link.at,
        f"no mass in the {source.noun}: {mass:.4g} kg, its visual solid's volume "
        f"({volume:.4g} m^3, "
        f"{what}) at {density:g} kg/m^3 (--density); CoM and inertia of that solid",
    )
    flat = (tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2])
    keys = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
    return {
        "mass": float(f"{mass:.6g}"),
        "com": [float(f"{c:.6g}") + 0.0 for c in com],
        "inertia": {k: float(f"{v:.9g}") + 0.0 for k, v in zip(keys, flat, strict=True)},
        "estimated": ["mass", "com", "inertia"],
        "note": f"massless in the {source.noun}; mass of its visual solid at {density:g} kg/m^3",
    }


#: up to this many collision sources are kept as the link's pieces (one convex hull each)
MAX_GIVEN = 10
#: at most this many given pieces in all: the kit merges them pairwise down to its ten
#: (derive/collision.py `merge_greedy`, quadratic in them: 48 pieces took 7.5 s, cover
#: included, where CoACD takes about 4 s a link); the spec allows 1000 (spec/bounds.py)
MAX_GIVEN_PIECES = 64
PRIMITIVES = {"box", "cylinder", "sphere", "capsule"}


def _collision(collisions: list[dict], sources: list[str]) -> dict:
    """Primitives stay primitives; the meshes of up to MAX_GIVEN sources (`sources`: each
    collision's source, its `piece_of` or its own: the pieces of one source count once),
    MAX_GIVEN_PIECES pieces in all, are kept, one convex piece each (`given`); more go to
    the cached CoACD path (`auto`); none means no collision geometry."""
    if all(c["shape"] in PRIMITIVES for c in collisions):
        return {"collision": "primitives", "collision_primitives": collisions}
    if len(set(sources)) <= MAX_GIVEN and len(collisions) <= MAX_GIVEN_PIECES:
        return {"collision": "given", "collision_shapes": collisions}
    return {"collision": "auto"}
