"""The kit is the URDF (or xacro) robot it was imported from: re-read the source URDF with
an independent reader (yourdfpy, not the importer's lxml walk) and compare its kinematics,
limits and mass properties with the kit's written URDF. Every difference must be listed,
with its reason, in robot.json's `source_differences`; any other fails, naming the joint or
link.

Names: `what` keys use the source's names (`joints.J.axis`, `links.L.mass`); a renamed
element is `links.L.name` / `joints.J.name` with the kit's name in `kit`; an element the kit
adds is `links.NAME` / `joints.NAME` (kit name), one the kit leaves out `links.L` (source).
Units: m, rad, kg, kg m^2, all in the link or joint frame the URDF defines.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.check.source import kit_usd as source_usd
from simkit.check.source import loops as source_loops
from simkit.check.source.shared import (
    ABS_LENGTH,
    REL,
    Allowed,
    inertia_close,
    unlisted_findings,
    vector_text,
)
from simkit.kitio.oneline import one_line

#: attributes holding numbers that the comparison reads (origins, axes, limits, inertials)
NUMERIC = {"xyz", "rpy", "value", "lower", "upper", "effort", "velocity", "damping", "friction"}
NUMERIC |= {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}
STRTOD = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")


def _strtod(text: str) -> str:
    """Each number as C's strtod reads it, as PyBullet and the importer do (`0.07, 0`,
    `-1.57.`): its longest leading number, separated by spaces."""
    found = (STRTOD.match(token) for token in re.split(r"[\s,]+", text.strip()) if token)
    return " ".join(m.group(0) for m in found if m)


def _comparable(path: Path, fixes: list[str] | None = None) -> bytes:
    """The URDF as the comparison reads it: without `<visual>` and `<collision>` (geometry is
    not compared, and yourdfpy refuses shapes it does not know, such as PyBullet's
    `<capsule>`), numbers read as strtod reads them. With a `fixes` list, the forms yourdfpy
    refuses and the importer reads leniently are read as the importer reads them too, and
    each fix applied is appended to the list (one phrase each)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    for parent in list(root.iter()):
        for child in list(parent):
            if child.tag in ("visual", "collision"):
                parent.remove(child)
            for key, text in child.attrib.items():
                if key in NUMERIC:
                    child.set(key, _strtod(text))
    if fixes is not None:
        fixes += _lenient(root)
    return ET.tostring(root, encoding="utf-8")


def _lenient(root) -> list[str]:
    """Read what the importer reads leniently and yourdfpy refuses (importer/read): a
    `<robot>` without a name (named after the file by the import), an origin of more than
    three numbers (its first three, as PyBullet reads it). The fixes applied, one phrase
    each."""
    out = []
    if not root.get("name"):
        root.set("name", "robot")
        out.append("the <robot> has no name")
    long = [e for e in root.iter("origin") for k in ("xyz", "rpy") if len(e.get(k, "").split()) > 3]
    for element in long:
        for key in ("xyz", "rpy"):
            element.set(key, " ".join(element.get(key, "0 0 0").split()[:3]))
    if long:
        out.append(f"{len(long)} origins of more than three numbers read as their first three")
    return out


def load_urdf(path: Path, fixes: list[str] | None = None):
    """The URDF's robot as yourdfpy reads it (kinematics and inertials; see `_comparable`;
    `fixes`: read leniently, the fixes applied appended to it)."""
    import io
    import logging

    import yourdfpy  # lazy: pulls in trimesh

    logging.getLogger("yourdfpy").setLevel(logging.ERROR)
    return yourdfpy.URDF.load(
        io.BytesIO(_comparable(path, fixes)),
        load_meshes=False,
        build_scene_graph=False,
        build_collision_scene_graph=False,
    ).robot


def _read_leniently(path: Path) -> tuple[object | None, list[str]]:
    """(yourdfpy's robot of the source read leniently, the fixes applied), or (None, ...)
    when no fix applies or yourdfpy still cannot read it."""
    fixes: list[str] = []
    try:
        robot = load_urdf(path, fixes)
    except Exception:  # yourdfpy raises several types on bad input
        return None, fixes
    return (robot if fixes else None), fixes


def remake(path: Path, args: dict[str, str]) -> bytes:
    """The kept URDF made anew from the original file the user imported (a URDF, or a xacro
    expanded with the import's `args`), read by the importer's reader as the import read it
    (formats/urdf.py `serialised`); SpecError when it cannot be read."""
    from simkit.importer import formats
    from simkit.importer.diagnostics import Report
    from simkit.importer.formats import urdf as urdf_format
    from simkit.importer.read.options import ReadOptions

    doc = formats.load(path, (), Report(), ReadOptions(tuple(sorted(args.items()))))
    return urdf_format.serialised(doc.kept)


def compare(kit: Kit, path: Path) -> list[Finding]:
    """The comparison of the URDF source at `path` (yourdfpy) with the kit's URDF, and of
    the source with the kit's USD (kit_usd.py)."""
    findings: list[Finding] = []
    try:
        source = load_urdf(path)
    except Exception as exc:  # yourdfpy raises several types on bad input
        why = " ".join(str(exc).split())[:200]
        source, fixes = _read_leniently(path)
        if source is None:
            fail = f"yourdfpy cannot read the source: {why}"
            return [*findings, require("source.read", False, fail)]
        said = (
            f"yourdfpy cannot read the source as written ({why}): compared with it read as "
            f"the importer reads it ({'; '.join(fixes)})"
        )
        findings.append(require("source.read", True, said))
    try:
        built = load_urdf(kit.path(kit.urdf))
    except Exception as exc:
        why = " ".join(str(exc).split())[:200]
        return [*findings, require("source.read", False, f"yourdfpy cannot read the kit: {why}")]
    allowed = Allowed.of(kit.doc)
    usd = source_usd.compare(kit, source_usd.source_of_urdf(source), allowed)
    loops = source_loops.compare(source.joints, kit.doc, allowed)
    return findings + compare_robots(source, built, allowed) + loops + usd


def compare_robots(source, built, allowed: Allowed) -> list[Finding]:
    """Findings for yourdfpy robots `source` and `built` (the kit's URDF)."""
    out: list[Finding] = []
    link_problems = _paired("link", source.links, built.links, allowed.links, allowed, _mass)
    joint_problems = _paired("joint", source.joints, built.joints, allowed.joints, allowed, _joint)
    out += unlisted_findings(
        "source.links",
        link_problems,
        f"{len(source.links)} links: names, masses, "
        "CoMs and inertias agree with the source or are listed differences",
    )
    out += unlisted_findings(
        "source.joints",
        joint_problems,
        f"{len(source.joints)} joints: names, "
        "types, parents, children, origins, axes and limits agree with the source "
        "or are listed differences",
    )
    return out


def _paired(kind: str, source: list, built: list, renames: dict, allowed: Allowed, compare):
    """Problems of one kind of element: each source element paired with the kit's (under its
    own or its listed name) and compared, and those only one side has, unless listed."""
    kit = {item.name: item for item in built}
    key, seen, problems = f"{kind}s", set(), []
    for item in source:
        name = _kit_name(renames, item.name, kit)
        if name not in kit:
            if f"{key}.{one_line(item.name)}" not in allowed.keys:
                problems.append(f"{kind} '{one_line(item.name)}' is missing from the kit")
            continue
        seen.add(name)
        problems += compare(item, kit[name], allowed)
    problems += [
        f"{kind} '{n}' is in the kit, not in the source"
        for n in sorted(set(kit) - seen)
        if f"{key}.{n}" not in allowed.keys
    ]
    return problems


def _kit_name(renames: dict[str, str], name: str, kit: dict) -> str:
    """The kit's name of source element `name`: as listed renamed, else its own."""
    new = renames.get(one_line(name), name)
    return new if new in kit or name not in kit else name


def _close(a, b, scale: float, floor: float) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return bool(np.all(np.abs(a - b) <= REL * scale + floor))


def _mass_properties(link) -> tuple[float, np.ndarray, np.ndarray]:
    """(mass kg, CoM m, inertia about the CoM in link axes kg m^2); zeros without inertial."""
    inertial = link.inertial
    if inertial is None:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    origin = np.eye(4) if inertial.origin is None else np.asarray(inertial.origin, dtype=float)
    tensor = np.zeros((3, 3)) if inertial.inertia is None else np.asarray(inertial.inertia)
    rot = origin[:3, :3]
    return float(inertial.mass or 0.0), origin[:3, 3].copy(), rot @ tensor @ rot.T


def _mass(src, kit, allowed: Allowed) -> list[str]:
    """Mass, CoM and inertia of one link, each unless listed."""
    key, shown = f"links.{one_line(src.name)}", one_line(src.name)
    m0, c0, i0 = _mass_properties(src)
    m1, c1, i1 = _mass_properties(kit)
    out = []
    if f"{key}.mass" not in allowed.keys and not _close(m0, m1, abs(m0), 0.0):
        out.append(f"link '{shown}': mass {m0:.9g} kg in the source, {m1:.9g} in the kit")
    if f"{key}.com" not in allowed.keys and not _close(
        c0, c1, float(np.max(np.abs(c0))), ABS_LENGTH
    ):
        out.append(
            f"link '{shown}': CoM {vector_text(c0)} m in the source, {vector_text(c1)} in the kit"
        )
    if f"{key}.inertia" not in allowed.keys and not inertia_close(i0, i1):
        out.append(
            f"link '{shown}': inertia (link axes) {vector_text(np.diag(i0))}"
            f" kg m^2 on the diagonal "
            f"in the source, {vector_text(np.diag(i1))} in the kit"
        )
    return out


def _joint(src, kit, allowed: Allowed) -> list[str]:
    """Type, parent, child, origin, axis and limits of one joint, each unless listed."""
    key, name = f"joints.{one_line(src.name)}", f"joint '{one_line(src.name)}'"
    out = []

    def differs(attr: str, a, b) -> None:
        if f"{key}.{attr}" not in allowed.keys:
            out.append(f"{name}: {attr} {a} in the source, {b} in the kit")

    if src.type != kit.type:
        differs("type", src.type, kit.type)
    for end in ("parent", "child"):
        want = allowed.links.get(one_line(getattr(src, end)), getattr(src, end))
        if want != getattr(kit, end):
            differs(end, getattr(src, end), getattr(kit, end))
    o0 = np.eye(4) if src.origin is None else np.asarray(src.origin, dtype=float)
    o1 = np.eye(4) if kit.origin is None else np.asarray(kit.origin, dtype=float)
    length = float(np.max(np.abs(o0[:3, 3])))
    same = _close(o0[:3, 3], o1[:3, 3], length, ABS_LENGTH)
    if not (same and _close(o0[:3, :3], o1[:3, :3], 1, 0)):
        differs(
            "origin",
            f"xyz {vector_text(o0[:3, 3])}",
            f"xyz {vector_text(o1[:3, 3])} (or its rotation)",
        )
    if src.type in ("fixed", "floating") or kit.type in ("fixed", "floating"):
        return out
    a0, a1 = _unit(src.axis), _unit(kit.axis)
    if not _close(a0, a1, 1, 0):
        differs("axis", vector_text(a0), vector_text(a1))
    out += _limits(src, kit, allowed, key, name)
    return out


def _limits(src, kit, allowed: Allowed, key: str, name: str) -> list[str]:
    """lower/upper (not for continuous), velocity and effort: URDF's <limit>."""
    out = []
    fields = [("max_velocity", "velocity"), ("effort_peak", "effort")]
    if src.type != "continuous" and kit.type != "continuous":
        fields = [("lower", "lower"), ("upper", "upper"), *fields]
    for attr, urdf_attr in fields:
        a = None if src.limit is None else getattr(src.limit, urdf_attr)
        b = None if kit.limit is None else getattr(kit.limit, urdf_attr)
        if f"{key}.{attr}" in allowed.keys:
            continue
        if a is None or b is None:
            if (a is None) != (b is None):
                out.append(f"{name}: {urdf_attr} {a} in the source, {b} in the kit")
            continue
        if not _close(a, b, abs(float(a)), 0.0):
            out.append(f"{name}: {urdf_attr} {float(a):.9g} in the source, {float(b):.9g} in kit")
    return out


def _unit(axis) -> np.ndarray:
    a = np.asarray((1.0, 0.0, 0.0) if axis is None else axis, dtype=float)
    norm = float(np.linalg.norm(a))
    return a / norm if norm > 0 else a
