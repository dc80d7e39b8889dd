"""A body's mass properties in its link frame: UsdPhysics MassAPI where authored, else the
solid of its collision shapes at the body's density (tree.py's module docstring).

A MassAPI that gives the mass and the principal moments (even zero ones) but no
`centerOfMass` puts the CoM at the body's origin: the author wrote the inertia about a point,
and the converters that write mass properties (NVIDIA's urdf-usd-converter) leave a zero CoM
unwritten. Without the moments, the CoM (and inertia) come from the colliders' solid, as
UsdPhysics says."""

from __future__ import annotations

import numpy as np

from simkit.importer.formats.usd import poses
from simkit.importer.read.model import At, Inertial

#: kg/m^3 where neither the body nor its colliders author a density (UsdPhysics' default)
DEFAULT_DENSITY = 1000.0
#: MassAPI's "not authored" centre of mass (its fallback is -inf on every axis)
UNSET = -1e30


def of_body(prim, name: str, colliders: list, frame: np.ndarray, ctx) -> tuple | None:
    """(mass kg, CoM m, principal axes 3x3, principal moments kg m^2), all in the link
    frame (`frame`: the link frame in the body frame) of link `name` with `colliders`
    (shapes.Collider); None when the body has neither a mass nor a collider (the translation
    estimates it from its visual, and says so)."""
    from pxr import UsdPhysics

    api = UsdPhysics.MassAPI(prim) if prim.HasAPI(UsdPhysics.MassAPI) else None
    kg = _value(api, "GetMassAttr", 0.0) * ctx.units.kilograms
    com = _value(api, "GetCenterOfMassAttr", None)
    diagonal = _value(api, "GetDiagonalInertiaAttr", None)
    axes = _value(api, "GetPrincipalAxesAttr", None)
    to_link = poses.inv(frame)
    solid = None
    if kg <= 0 or com is None or diagonal is None:
        density = _value(api, "GetDensityAttr", 0.0) or DEFAULT_DENSITY
        density *= ctx.units.kilograms / ctx.units.meters**3
        solid = _solid(colliders, density)
        if solid is None and kg <= 0:
            return None
    key = f"links.{name}"
    if kg <= 0:
        kg = solid[0]
        ctx.listed.append((f"{key}.mass", "no MassAPI mass: the colliders' solid at its density"))
    given = diagonal is not None  # authored, even as zero: the author wrote the inertia
    if given and kg > 0 and (com is None or not np.all(np.asarray(com) > UNSET)):
        com = (0.0, 0.0, 0.0)  # inertia given about a CoM left unwritten: the body origin
    if com is not None and np.all(np.asarray(com) > UNSET):
        scale = poses.world(ctx.cache, prim, 1.0)[1]
        centre = to_link[:3, :3] @ (np.asarray(com, float) * scale * ctx.units.meters)
        centre = centre + to_link[:3, 3]
    else:
        centre = solid[1] if solid is not None else np.zeros(3)
        ctx.listed.append((f"{key}.com", "no MassAPI centerOfMass: the colliders' solid's"))
    if diagonal is not None and np.any(np.asarray(diagonal) > 0):
        moments = np.asarray(diagonal, float) * ctx.units.kilograms * ctx.units.meters**2
        turn = poses.quat_matrix(axes) if axes is not None else np.eye(3)
        return kg, centre, to_link[:3, :3] @ turn, moments
    ctx.listed.append((f"{key}.inertia", "no MassAPI diagonalInertia: the colliders' solid's"))
    if solid is None:
        return kg, centre, np.eye(3), np.zeros(3)
    tensor = solid[2] * (kg / solid[0])
    moments, turn = np.linalg.eigh(tensor)
    if np.linalg.det(turn) < 0:
        turn[:, 0] = -turn[:, 0]
    return kg, centre, turn, moments


def inertial(found: tuple | None) -> Inertial | None:
    """The `Inertial` of mass.of_body's (kg, CoM, principal axes, moments): the inertia's
    principal moments in the axes' frame, as the URDF reader reads an `<inertial>` (no
    inertia where the mass is not positive)."""
    if found is None:
        return None
    kg, com, rot, diagonal = found
    mass = float(kg)
    inertia = (*poses.floats(diagonal), 0.0, 0.0, 0.0) if mass > 0 else None
    return Inertial(
        At("inertial"),
        poses.pose(poses.make(rot, com)),
        mass,
        At("mass"),
        inertia,  # type: ignore[arg-type]
        At("inertia"),
    )


def _value(api, getter: str, default):
    """An authored MassAPI attribute's value, else `default`."""
    if api is None:
        return default
    attr = getattr(api, getter)()
    if not attr or not attr.HasAuthoredValue():
        return default
    value = poses.get(api.GetPrim(), attr.GetName())
    return float(value) if isinstance(default, float) else value


def _solid(colliders: list, density: float) -> tuple[float, np.ndarray, np.ndarray] | None:
    """(mass kg, CoM m, inertia about the CoM kg m^2) of the link's collision shapes
    (link frame; `colliders`: shapes.Collider), each at its own MassAPI density or mass, else
    `density`; primitives exactly, a mesh as its closed solid (else its convex hull). None
    without a collider of positive volume."""
    pieces = []
    for collider in colliders:
        own_density = collider.density or density
        piece = _piece(collider.geometry.shape)
        if piece is None or piece[0] <= 0:
            continue
        volume, centre, unit = piece
        mass = collider.mass or own_density * volume
        origin = collider.geometry.origin
        xyz = np.array(origin.xyz, dtype=float)
        turn = _rpy_matrix(origin.rpy)
        pieces.append((mass, turn @ centre + xyz, turn @ (unit * mass / volume) @ turn.T))
    total = sum(p[0] for p in pieces)
    if total <= 0:
        return None
    com = sum(p[0] * p[1] for p in pieces) / total
    tensor = np.zeros((3, 3))
    for mass, centre, inertia in pieces:
        d = centre - com
        tensor += inertia + mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return float(total), com, tensor


def _rpy_matrix(rpy) -> np.ndarray:
    r, p, y = rpy
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    return rz @ ry @ rx


def _piece(shape) -> tuple[float, np.ndarray, np.ndarray] | None:
    """(volume m^3, centroid m, inertia about the centroid at unit density kg m^2) of one
    model `Shape` in its own frame; None for a shape without volume."""
    import math

    if shape.kind == "box":
        a, b, c = shape.size
        v = a * b * c
        return v, np.zeros(3), v / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    if shape.kind == "sphere":
        r = shape.radius
        v = 4.0 / 3.0 * math.pi * r**3
        return v, np.zeros(3), np.eye(3) * 0.4 * v * r * r
    if shape.kind in ("cylinder", "capsule"):
        r, h = shape.radius, shape.length
        vc = math.pi * r * r * h
        side, axial = vc * (3 * r * r + h * h) / 12.0, vc * r * r / 2.0
        v = vc
        if shape.kind == "capsule":  # two hemispheres at the ends
            vs = 4.0 / 3.0 * math.pi * r**3
            side += vs * (0.4 * r * r + h * h / 4.0 + 3.0 * h * r / 8.0)
            axial += vs * 0.4 * r * r
            v += vs
        return v, np.zeros(3), np.diag([side, side, axial])
    if shape.kind == "mesh":
        import trimesh

        mesh = trimesh.load_mesh(shape.filename)
        if not (mesh.is_watertight and mesh.volume > 0):
            mesh = mesh.convex_hull
        if mesh.volume <= 0:
            return None
        mesh.density = 1.0
        return float(mesh.volume), np.asarray(mesh.center_mass), np.asarray(mesh.moment_inertia)
    return None
