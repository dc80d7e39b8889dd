"""A body's mass properties in its link frame: UsdPhysics MassAPI where authored, else the
solid of its collision shapes at the body's density (tree.py's module docstring).

A MassAPI that gives the mass and the principal moments but no `centerOfMass` puts the CoM at
the body's origin: the author computed the inertia about a point, and the converters that
write mass properties (NVIDIA's urdf-usd-converter) leave a zero CoM unwritten. Without the
inertia, the CoM (and inertia) come from the colliders' solid, as UsdPhysics says."""

from __future__ import annotations

import numpy as np

from simkit.importer.formats.usd import poses

#: kg/m^3 where neither the body nor its colliders author a density (UsdPhysics' default)
DEFAULT_DENSITY = 1000.0
#: MassAPI's "not authored" centre of mass (its fallback is -inf on every axis)
UNSET = -1e30


def of_body(prim, link, frame: np.ndarray, ctx) -> tuple | None:
    """(mass kg, CoM m, principal axes 3x3, principal moments kg m^2), all in the link
    frame (`frame`: the link frame in the body frame); None when the body has neither a
    mass nor a collider (the translation estimates it from its visual, and says so)."""
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
        solid = _solid(link, density)
        if solid is None and kg <= 0:
            return None
    if kg <= 0:
        kg = solid[0]
        ctx.listed.append(
            (
                f"links.{link.get('name')}.mass",
                "no MassAPI mass: the colliders' solid at its density",
            )
        )
    given = diagonal is not None and np.any(np.asarray(diagonal) > 0)
    if given and kg > 0 and (com is None or not np.all(np.asarray(com) > UNSET)):
        com = (0.0, 0.0, 0.0)  # inertia given about a CoM left unwritten: the body origin
    if com is not None and np.all(np.asarray(com) > UNSET):
        scale = poses.world(ctx.cache, prim, 1.0)[1]
        centre = to_link[:3, :3] @ (np.asarray(com, float) * scale * ctx.units.meters)
        centre = centre + to_link[:3, 3]
    else:
        centre = solid[1] if solid is not None else np.zeros(3)
    if diagonal is not None and np.any(np.asarray(diagonal) > 0):
        moments = np.asarray(diagonal, float) * ctx.units.kilograms * ctx.units.meters**2
        turn = poses.quat_matrix(axes) if axes is not None else np.eye(3)
        return kg, centre, to_link[:3, :3] @ turn, moments
    if solid is None:
        return kg, centre, np.eye(3), np.zeros(3)
    tensor = solid[2] * (kg / solid[0])
    moments, turn = np.linalg.eigh(tensor)
    if np.linalg.det(turn) < 0:
        turn[:, 0] = -turn[:, 0]
    return kg, centre, turn, moments


def _value(api, getter: str, default):
    """An authored MassAPI attribute's value, else `default`."""
    if api is None:
        return default
    attr = getattr(api, getter)()
    if not attr or not attr.HasAuthoredValue():
        return default
    value = poses.get(api.GetPrim(), attr.GetName())
    return float(value) if isinstance(default, float) else value


def _solid(link, density: float) -> tuple[float, np.ndarray, np.ndarray] | None:
    """(mass kg, CoM m, inertia about the CoM kg m^2) of the link's `<collision>` shapes
    (link frame) at `density`; None without a collider of positive volume."""
    import trimesh

    pieces = []
    for collision in link.findall("collision"):
        mesh = _mesh(collision.find("geometry")[0])
        if mesh is None:
            continue
        xyz = [float(v) for v in collision.find("origin").get("xyz").split()]
        rpy = [float(v) for v in collision.find("origin").get("rpy").split()]
        mesh.apply_transform(trimesh.transformations.compose_matrix(angles=rpy, translate=xyz))
        pieces.append(mesh)
    if not pieces:
        return None
    solid = trimesh.util.concatenate(pieces)
    solid.density = density
    if solid.volume <= 0:
        return None
    return float(solid.mass), np.asarray(solid.center_mass), np.asarray(solid.moment_inertia)


def _mesh(shape):
    """A trimesh solid of one URDF geometry element (closed; a mesh's convex hull)."""
    import trimesh

    if shape.tag == "box":
        return trimesh.creation.box([float(v) for v in shape.get("size").split()])
    if shape.tag == "sphere":
        return trimesh.creation.icosphere(4, float(shape.get("radius")))
    if shape.tag in ("cylinder", "capsule"):
        make = trimesh.creation.cylinder if shape.tag == "cylinder" else trimesh.creation.capsule
        kwargs = {"radius": float(shape.get("radius"))}
        kwargs["height"] = float(shape.get("length"))
        return (
            make(**kwargs, sections=64)
            if shape.tag == "cylinder"
            else make(**kwargs, count=[32, 32])
        )
    if shape.tag == "mesh":
        mesh = trimesh.load_mesh(shape.get("filename"))
        return mesh if mesh.is_watertight and mesh.volume > 0 else mesh.convex_hull
    return None
