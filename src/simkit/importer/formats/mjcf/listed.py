"""What an MJCF holds that a kit does not carry, listed (`source_differences`), and the
joint effort its actuators give.

A kit carries a robot's links, joints, frames, geometry and one servo per joint; MuJoCo's
tendons, equality constraints, cameras, lights, keyframes, sensors, contact pairs,
actuators that drive anything but one joint, and its own servo gains have no place in the
spec. Each is listed with its reason (key `KIND.NAME`), never dropped silently. Contact
excludes are carried (excludes.py).
"""

from __future__ import annotations

import numpy as np

#: mjtTrn: joint, joint in parent; mjtGain/mjtBias: fixed, none
JOINT_TRANSMISSIONS = (0, 1)

#: (MjModel count, element accessor, what, reason)
KINDS = (
    ("ntendon", "tendon", "tendons", "a kit has no tendons (URDF, SDF and USD cannot hold one)"),
    ("neq", "eq", "equality", "a kit holds no equality constraints but its mimic joints"),
    ("ncam", "cam", "cameras", "a kit carries no cameras"),
    ("nlight", "light", "lights", "a kit carries no lights"),
    ("nkey", "key", "keyframes", "a kit's poses are its own (home and the named poses)"),
    ("nsensor", "sensor", "sensors", "a kit's MuJoCo sensors are its own"),
    ("npair", "pair", "contact_pairs", "a kit's contact pairs are its own (self-collision)"),
    ("nskin", "skin", "skins", "a kit carries no skins"),
    ("nflex", "flex", "flexes", "a kit has no deformable bodies"),
)


def _name(model, accessor: str, index: int) -> str:
    return getattr(model, accessor)(index).name or f"{accessor}{index}"


def collect(model, root: int, bodies: list[int]) -> list[tuple[str, str]]:
    """(what, reason) of each MJCF element the kit leaves out."""
    out: list[tuple[str, str]] = []
    for count, accessor, what, reason in KINDS:
        for i in range(int(getattr(model, count, 0))):
            out.append((f"{what}.{_name(model, accessor, i)}", reason))
    kept = set(bodies)
    for b in range(1, model.nbody):
        if b not in kept:
            out.append((f"links.{_name(model, 'body', b)}", "a body outside the robot's tree"))
    for g in range(model.ngeom):
        body, kind = int(model.geom_bodyid[g]), int(model.geom_type[g])
        if body in kept and kind not in (2, 3, 5, 6, 7):
            out.append((f"geoms.{_name(model, 'geom', g)}", "a shape the kit formats lack"))
        elif body in kept and kind == 7 and flat(model, int(model.geom_dataid[g])):
            out.append((f"geoms.{_name(model, 'geom', g)}", "a flat mesh: no closed solid"))
        elif body not in kept:
            out.append((f"geoms.{_name(model, 'geom', g)}", "geometry outside the robot's tree"))
    for a in range(model.nu):
        name = _name(model, "actuator", a)
        if model.actuator_trntype[a] not in JOINT_TRANSMISSIONS:
            out.append((f"actuators.{name}", "drives a tendon, site or body: not one joint"))
        else:
            out.append((f"actuators.{name}.gains", "the kit's servo gains are simkit's own"))
    for j in range(model.njnt):
        dof = int(model.jnt_dofadr[j])
        if model.dof_armature[dof]:
            out.append(
                (f"joints.{_name(model, 'jnt', j)}.armature", "the kit's armature is estimated")
            )
        if model.jnt_stiffness[j]:
            out.append((f"joints.{_name(model, 'jnt', j)}.stiffness", "a kit joint has no spring"))
        if model.jnt_type[j] == 1 and model.jnt_limited[j]:
            out.append(
                (f"joints.{_name(model, 'jnt', j)}.range", "a ball's cone limit: three free joints")
            )
    if model.body_pos[root].any() or (model.body_quat[root] != (1, 0, 0, 0)).any():
        out.append((f"links.{_name(model, 'body', root)}.pose", "the kit places its root itself"))
    return out


def flat(model, mesh: int) -> bool:
    """Whether a compiled mesh encloses no volume, even as its convex hull (a decal, a
    screen drawn as one sheet): a kit's solid must be closed, so the geom is listed."""
    import manifold3d as mf

    start, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    points = np.asarray(model.mesh_vert[start : start + count], dtype=np.float32)
    if len(points) < 4:
        return True
    hull = mf.Manifold.hull_points(points)
    extent = float(np.ptp(points, axis=0).max())
    return hull.is_empty() or hull.volume() <= 1e-9 * extent**3


def effort(model, j: int) -> float | None:
    """The largest generalized force (N m or N) the joint's actuators can apply, None when
    any of them is unbounded: per actuator |gear| x (its force range, else its control range
    times a fixed gain without bias), capped by the joint's `actuatorfrcrange`."""
    total, bounded = 0.0, False
    for a in range(model.nu):
        if model.actuator_trntype[a] not in JOINT_TRANSMISSIONS or model.actuator_trnid[a][0] != j:
            continue
        limits = []
        if model.actuator_forcelimited[a]:
            limits.append(float(np.max(np.abs(model.actuator_forcerange[a]))))
        plain = model.actuator_gaintype[a] == 0 and model.actuator_biastype[a] == 0
        if model.actuator_ctrllimited[a] and plain and model.actuator_dyntype[a] == 0:
            limits.append(
                float(np.max(np.abs(model.actuator_ctrlrange[a])))
                * abs(float(model.actuator_gainprm[a][0]))
            )
        if not limits:
            return _capped(model, j, None)
        total += abs(float(model.actuator_gear[a][0])) * min(limits)
        bounded = True
    return _capped(model, j, total if bounded and total > 0 else None)


def _capped(model, j: int, value: float | None) -> float | None:
    if not model.jnt_actfrclimited[j]:
        return value
    cap = float(np.max(np.abs(model.jnt_actfrcrange[j])))
    return cap if value is None else min(cap, value)
