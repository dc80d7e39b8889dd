"""The source proof reads the composed USD stage too (issue 33).

`source.links` and `source.joints` compare the source with the kit's URDF (or, for an MJCF
source, both compiled in MuJoCo), and the `usd` checks compare the USD with the MJCF. This
closes the loop directly: the kit's entry USD is composed (its default physics variant, every
payload loaded) and each body's `physics:mass`, each movable joint's type and limits are
compared with the source's, under the kit's names, unless robot.json's `source_differences`
lists them. USD stores float32, so values agree within `REL` of their size.
"""

from __future__ import annotations

import math
from pathlib import Path

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.check.readers.usd import prim_name
from simkit.kitio import layout

CHECK = "source.usd"
#: relative agreement of a float32 USD value with the source's float64
REL = 1e-6
#: deg or m: agreement floor for limits at zero
FLOOR = 1e-6


def source_of_urdf(robot) -> tuple[dict[str, float], dict[str, tuple]]:
    """({link: mass kg}, {joint: (kind, (lower, upper) in deg or m, or None)}) of a yourdfpy
    robot; continuous joints are revolute without limits."""
    masses = {link.name: float(link.inertial.mass or 0.0) for link in robot.links if link.inertial}
    joints = {}
    for joint in robot.joints:
        if joint.type not in ("revolute", "continuous", "prismatic"):
            continue
        kind = "prismatic" if joint.type == "prismatic" else "revolute"
        span = None
        if joint.type != "continuous" and joint.limit is not None:
            span = _units(kind, joint.limit.lower, joint.limit.upper)
        joints[joint.name] = (kind, span)
    return masses, joints


def source_of_mjcf(model) -> tuple[dict[str, float], dict[str, tuple]]:
    """The same from a compiled MuJoCo model of the source (hinge and slide joints)."""
    import mujoco

    masses = {model.body(b).name: float(model.body_mass[b]) for b in range(1, model.nbody)}
    kinds = {
        int(mujoco.mjtJoint.mjJNT_HINGE): "revolute",
        int(mujoco.mjtJoint.mjJNT_SLIDE): "prismatic",
    }
    joints = {}
    for j in range(model.njnt):
        kind = kinds.get(int(model.jnt_type[j]))
        if kind is not None:
            span = _units(kind, *model.jnt_range[j]) if model.jnt_limited[j] else None
            joints[model.joint(j).name] = (kind, span)
    return masses, joints


def _units(kind: str, lower, upper) -> tuple[float, float] | None:
    if lower is None or upper is None:
        return None
    scale = math.degrees(1.0) if kind == "revolute" else 1.0
    return float(lower) * scale, float(upper) * scale


def _stage_contents(path: Path) -> tuple[dict[str, float], dict[str, tuple]]:
    """({body prim name: mass}, {joint prim name: (kind, (lower, upper) or None)})."""
    from pxr import Usd, UsdPhysics

    stage = Usd.Stage.Open(str(path), Usd.Stage.LoadAll)
    masses, joints = {}, {}
    for prim in stage.Traverse():
        if prim.HasAPI(UsdPhysics.MassAPI):
            mass = UsdPhysics.MassAPI(prim).GetMassAttr().Get()
            if mass is not None:
                masses[prim.GetName()] = float(mass)
        for kind, schema in (
            ("revolute", UsdPhysics.RevoluteJoint),
            ("prismatic", UsdPhysics.PrismaticJoint),
        ):
            if prim.IsA(schema):
                joint = schema(prim)
                low, high = joint.GetLowerLimitAttr().Get(), joint.GetUpperLimitAttr().Get()
                finite = (
                    low is not None and high is not None and abs(low) < 1e30 and abs(high) < 1e30
                )
                joints[prim.GetName()] = (kind, (float(low), float(high)) if finite else None)
    return masses, joints


def _close(a: float, b: float) -> bool:
    return abs(a - b) <= REL * max(abs(a), abs(b)) + FLOOR


def _mass_problems(masses: dict, usd_masses: dict, allowed) -> tuple[list[str], int]:
    problems, compared = [], 0
    for name, mass in sorted(masses.items()):
        prim = prim_name(allowed.links.get(name, name))
        if prim not in usd_masses or f"links.{name}.mass" in allowed.keys:
            continue
        compared += 1
        if not _close(mass, usd_masses[prim]):
            got = usd_masses[prim]
            problems.append(
                f"link '{name}': mass {mass:.9g} kg in the source, {got:.9g} in the USD"
            )
    return problems, compared


def _joint_problems(joints: dict, usd_joints: dict, allowed) -> tuple[list[str], int]:
    problems, compared = [], 0
    for name, (kind, span) in sorted(joints.items()):
        prim = prim_name(allowed.joints.get(name, name))
        if prim not in usd_joints or f"joints.{name}" in allowed.keys:
            continue
        compared += 1
        got_kind, got_span = usd_joints[prim]
        if got_kind != kind and f"joints.{name}.type" not in allowed.keys:
            problems.append(f"joint '{name}': {kind} in the source, {got_kind} in the USD")
        # a listed type (a placeholder span made continuous) or bound: the USD follows the kit
        listed = {f"joints.{name}.{attr}" for attr in ("type", "lower", "upper")} & allowed.keys
        if span is None or listed:
            continue
        if got_span is None or not all(_close(a, b) for a, b in zip(span, got_span, strict=True)):
            problems.append(f"joint '{name}': limits {span} in the source, {got_span} in the USD")
    return problems, compared


def compare(kit: Kit, source: tuple[dict, dict], allowed) -> list[Finding]:
    """Findings for the source's (masses, joints) against the kit's composed USD stage;
    `allowed` is source.py's `Allowed` (listed keys and renames)."""
    name = kit.doc.get("name")
    path = kit.path(layout.usd(name)) if name else None
    if path is None or not path.is_file():
        return []  # a kit without USD: the other source findings hold
    usd_masses, usd_joints = _stage_contents(path)
    mass_problems, masses = _mass_problems(source[0], usd_masses, allowed)
    joint_problems, joints = _joint_problems(source[1], usd_joints, allowed)
    problems = mass_problems + joint_problems
    if problems:
        return [
            require(CHECK, False, p + " (not listed in source_differences)") for p in problems[:20]
        ]
    detail = (
        f"{masses} link masses and {joints} movable joints of the composed USD stage agree "
        "with the source"
    )
    return [require(CHECK, masses + joints > 0 or not any(source), detail)]
