"""The kit is the USD robot it was imported from: the kept layers are laid out again, the
stage composed (with the variant the import read, robot.json `source.args.variant`) and
parsed by usd-core's own UsdPhysics parser (`LoadUsdPhysicsFromRange`: bodies, joints, their
frames, axes and limits), not the importer's reader; the kit's URDF is read by yourdfpy.
Compared, under the source's prim names (made unique in path order, renames from robot.json):

- joint types (revolute, continuous for an unbounded revolute, prismatic, fixed; a
  spherical joint as the kit's three revolute joints J_x, J_y, J), limits (degrees to rad)
  and efforts (N m or N: `simkit:effortLimit` where the joint carries it, as a simkit kit's
  USD does, else the drive's maxForce, as the import reads them; listed as
  `joints.NAME.effort_peak` where the import estimated it), damping and friction loss
  (MjcPhysics `mjc:damping`, `mjc:frictionloss`, read off the composed stage since the
  parser has no field for them; other Physics variants fill what the read one lacks, as
  the import reads them: stage.py, dynamics.py) against the kit URDF's `<dynamics>`, and
  the armature against robot.json's;
- every body's MassAPI mass (kg, <= 1e-6 relative), CoM and inertia in the body frame;
- the pose of every body relative to the root body at 100 seeded configurations (1e-6 m,
  1e-6 in rotation): the source's composed from the parser's joint frames
  (body1 = body0 * localPose0 * motion(q) * localPose1^-1), the kit's from its URDF.

Frames: the kit's link frame of a body is its body frame moved (not turned) to the joint
frame on it (importer/formats/usd/tree.py); stage.py finds that frame from the parser's
joints and the same breadth-first walk. A difference passes only where `source_differences`
lists it.

The package: this module lays the kept layers out and compares (the findings); stage.py
reads the composed stage (the pxr side), so each stays one topic and under the size rule.
"""

from __future__ import annotations

import hashlib
import math
import tempfile
from pathlib import Path, PurePosixPath

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.check.source import kit_usd
from simkit.check.source.shared import (
    ABS_LENGTH,
    REL,
    SHOWN,
    Allowed,
    inertia_close,
    unlisted_findings,
    vector_text,
)
from simkit.check.source.urdf import load_urdf
from simkit.check.source.usd.stage import Body, Joint, Robot, source_robot
from simkit.kitio.oneline import one_line

__all__ = [
    "FK_TOL",
    "SEEDS",
    "Body",
    "Joint",
    "Robot",
    "compare",
    "kit_poses",
    "remake",
    "source_robot",
]

SEEDS = 100
#: m and rotation-matrix entries: FK agreement
FK_TOL = 1e-6


def remake(path: Path, args: dict[str, str]) -> bytes:
    """The kept root layer made from the original: it is kept byte for byte."""
    return path.read_bytes()


def compare(kit: Kit, path: Path) -> list[Finding]:
    """Findings for the USD at `path` (its other layers beside it or kept in the kit)
    against the kit's URDF, differences allowed where robot.json lists them."""
    recorded = kit.doc.get("source") or {}
    if hashlib.sha256(path.read_bytes()).hexdigest() != recorded.get("sha256"):
        return []  # not the file the import read (source.digest fails): never composed
    variant = (recorded.get("args") or {}).get("variant")
    with tempfile.TemporaryDirectory(prefix="simkit-source-") as tmp:
        folder = Path(tmp)
        problems = _lay_out(path, recorded.get("assets") or {}, folder)
        if problems:
            return [require("source.digest", False, p) for p in problems[:SHOWN]]
        try:
            source = source_robot(folder / path.name, variant)
        except Exception as exc:  # pxr raises Tf errors on a stage it cannot compose
            why = " ".join(str(exc).split())[:200]
            return [require("source.read", False, f"usd-core cannot read the source: {why}")]
    try:
        built = load_urdf(kit.path(kit.urdf))
    except Exception as exc:
        why = " ".join(str(exc).split())[:200]
        return [require("source.read", False, f"yourdfpy cannot read the kit: {why}")]
    allowed = Allowed.of(kit.doc)
    declared = kit.doc.get("joints") or []  # robot.json's; none: no armature compared
    joints = _joints(source, built, allowed) + _armatures(source, declared, allowed)
    out = unlisted_findings("source.joints", joints, _said(source, "joints"))
    out += unlisted_findings(
        "source.links", _bodies(source, built, allowed), _said(source, "links")
    )
    fk = _fk(source, built, allowed)
    out += unlisted_findings("source.fk", fk, f"every body's pose agrees at {SEEDS} configurations")
    return out + kit_usd.compare(kit, _for_kit_usd(source), allowed)


def _for_kit_usd(source: Robot) -> tuple[dict[str, float], dict[str, tuple]]:
    """The source's ({body: mass}, {joint: (kind, limits in deg or m)}) for kit_usd.py."""
    masses = {n: b.mass for n, b in source.bodies.items() if b.mass is not None}
    joints = {}
    for name, j in source.joints.items():
        if j.kind in ("revolute", "prismatic"):
            span = j.limits
            if span is not None and j.kind == "revolute":
                span = (math.degrees(span[0]), math.degrees(span[1]))
            joints[name] = (j.kind, span)
    return masses, joints


def _said(source: Robot, what: str) -> str:
    if what == "joints":
        return f"{len(source.joints)} joints: types and limits agree with the USD's physics parser"
    return f"{len(source.bodies)} bodies: MassAPI masses, CoMs and inertias agree"


def _lay_out(main: Path, assets: dict, folder: Path) -> list[str]:
    """The root layer and its recorded layers in `folder` as the import read them; problems:
    a layer missing, outside the folder, or not the recorded one."""
    (folder / main.name).write_bytes(main.read_bytes())
    kept = main.parent / (main.name.rsplit(".", 1)[0] + ".assets")
    problems = []
    for rel, digest in sorted(assets.items()):
        target = (folder / rel).resolve()
        if folder.resolve() not in target.parents or ".." in rel.split("/"):
            problems.append(f"layer '{rel}' lies outside the source's folder")
            continue
        for candidate in (main.parent / rel, kept / f"{digest}{PurePosixPath(rel).suffix.lower()}"):
            if candidate.is_file() and hashlib.sha256(candidate.read_bytes()).hexdigest() == digest:
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(candidate.read_bytes())
                break
        else:
            problems.append(f"layer '{rel}' is missing or not the one the import read")
    return problems


def _kit_name(table: dict[str, str], name: str) -> str:
    return table.get(one_line(name), name)


def _joints(source: Robot, built, allowed: Allowed) -> list[str]:
    """Each source joint in the kit: its type, and its limits (rad or m)."""
    kit = {j.name: j for j in built.joints}
    out = []
    for name, joint in sorted(source.joints.items()):
        key = f"joints.{name}"
        if key in allowed.keys:
            continue
        parts = (f"{name}_x", f"{name}_y", name) if joint.kind == "spherical" else (name,)
        found = [kit.get(_kit_name(allowed.joints, p)) for p in parts]
        if any(f is None for f in found):
            out.append(f"joint '{name}' is missing from the kit")
            continue
        want = _kit_type(joint)
        got = "spherical" if joint.kind == "spherical" else found[0].type
        if joint.kind == "spherical":
            got = "spherical" if all(f.type in ("revolute", "continuous") for f in found) else "?"
        if want != got and f"{key}.type" not in allowed.keys:
            out.append(f"joint '{name}': {want} in the USD, {got} in the kit")
        if want in ("revolute", "prismatic", "continuous") and want == got:
            out += _limits(name, joint, found[0], allowed)
    return out


def _kit_type(joint) -> str:
    if joint.kind == "revolute" and joint.limits is None:
        return "continuous"
    return joint.kind


def _limits(name: str, joint, kit, allowed: Allowed) -> list[str]:
    """lower and upper (rad or m; none for a continuous joint) and the effort."""
    out = []
    for i, attr in enumerate(("lower", "upper")):
        if joint.limits is None or f"joints.{name}.{attr}" in allowed.keys:
            continue
        want = joint.limits[i]
        got = None if kit.limit is None else getattr(kit.limit, attr)
        if got is None or abs(float(got) - want) > REL * abs(want) + ABS_LENGTH:
            out.append(f"joint '{name}': {attr} {want:.9g} in the USD, {got} in the kit")
    return out + _effort(name, joint, kit, allowed) + _dynamics(name, joint, kit, allowed)


def _dynamics(name: str, joint, kit, allowed: Allowed) -> list[str]:
    """The source's damping and friction loss (stage.py reads them off the stage: the parser
    has no field for them) against the kit's URDF `<dynamics>`; 0 where either gives none."""
    out = []
    for key in ("damping", "friction"):
        if f"joints.{name}.{key}" in allowed.keys or key not in joint.dynamics:
            continue
        want = joint.dynamics[key]
        got = getattr(kit.dynamics, key, None) if kit.dynamics is not None else None
        got = float(got or 0.0)
        if abs(got - want) > REL * want + 1e-12:
            out.append(f"joint '{name}': {key} {want:.9g} in the USD, {got:.9g} in the kit")
    return out


def _effort(name: str, joint, kit, allowed: Allowed) -> list[str]:
    """The source's effort limit (N m or N, where it carries one) against the kit's."""
    if joint.effort is None or f"joints.{name}.effort_peak" in allowed.keys:
        return []
    got = None if kit.limit is None else kit.limit.effort
    if got is None or abs(float(got) - joint.effort) > REL * joint.effort:
        return [f"joint '{name}': effort {joint.effort:.9g} in the USD, {got} in the kit"]
    return []


def _armatures(source: Robot, declared: list[dict], allowed: Allowed) -> list[str]:
    """The source's armature (kg m^2 or kg, where it gives one) against robot.json's."""
    kit = {j.get("name"): j.get("armature") for j in declared}
    out = []
    for name, joint in sorted(source.joints.items()):
        want = joint.dynamics.get("armature")
        if want is None or f"joints.{name}.armature" in allowed.keys:
            continue
        got = kit.get(_kit_name(allowed.joints, name))
        if got is None or abs(float(got) - want) > REL * want:
            out.append(f"joint '{name}': armature {want:.9g} in the USD, {got} in the kit")
    return out


def _bodies(source: Robot, built, allowed: Allowed) -> list[str]:
    """Each body's authored mass, CoM and inertia (body frame) against the kit's link."""
    kit = {link.name: link for link in built.links}
    out = []
    for name, body in sorted(source.bodies.items()):
        link = kit.get(_kit_name(allowed.links, name))
        key = f"links.{name}"
        if link is None:
            if key not in allowed.keys:
                out.append(f"link '{name}' is missing from the kit")
            continue
        if body.mass is None:
            continue
        inertial = link.inertial
        mass = 0.0 if inertial is None else float(inertial.mass or 0.0)
        if f"{key}.mass" not in allowed.keys and abs(mass - body.mass) > REL * body.mass:
            out.append(f"link '{name}': mass {body.mass:.9g} kg in the USD, {mass:.9g} in the kit")
        if inertial is None or inertial.origin is None:
            continue
        pose = body.frame @ np.asarray(inertial.origin, dtype=float)
        com = pose[:3, 3]
        far = None if body.com is None else np.max(np.abs(com - body.com))
        bound = 0.0 if body.com is None else REL * np.max(np.abs(body.com)) + ABS_LENGTH
        if far is not None and f"{key}.com" not in allowed.keys and far > bound:
            out.append(
                f"link '{name}': CoM {vector_text(body.com)}"
                f" m in the USD, {vector_text(com)} in the kit"
            )
        if body.inertia is not None and f"{key}.inertia" not in allowed.keys:
            tensor = pose[:3, :3] @ np.asarray(inertial.inertia) @ pose[:3, :3].T
            if not inertia_close(body.inertia, tensor):
                out.append(f"link '{name}': inertia (body axes) differs from the USD's")
    return out


def _fk(source: Robot, built, allowed: Allowed) -> list[str]:
    """Every body's pose relative to the root body at SEEDS seeded configurations."""
    rng = np.random.default_rng(0)
    movable = [j for j in built.joints if j.type in ("revolute", "continuous", "prismatic")]
    back = {v: k for k, v in allowed.joints.items()}
    names = {k: _kit_name(allowed.links, k) for k in source.bodies}
    out: list[str] = []
    for _ in range(SEEDS):
        q = {}
        for joint in movable:
            low, high = -math.pi, math.pi
            if joint.type != "continuous" and joint.limit is not None:
                low = -1.0 if joint.limit.lower is None else float(joint.limit.lower)
                high = 1.0 if joint.limit.upper is None else float(joint.limit.upper)
            q[joint.name] = float(rng.uniform(low, high))
        wanted = source.poses({back.get(k, k): v for k, v in q.items()})
        got = kit_poses(built, q)
        root = source.root
        if names[root] not in got:
            return [f"root link '{root}' is missing from the kit"]
        base = got[names[root]] @ np.linalg.inv(source.bodies[root].frame)
        for name, pose in sorted(wanted.items()):
            link = names.get(name)
            if link not in got or f"links.{name}" in allowed.keys:
                continue
            kit = np.linalg.inv(base) @ got[link] @ np.linalg.inv(source.bodies[name].frame)
            far = np.max(np.abs(kit[:3, 3] - pose[:3, 3]))
            if far > FK_TOL or np.max(np.abs(kit[:3, :3] - pose[:3, :3])) > FK_TOL:
                out.append(f"link '{name}': pose differs by {far:.3g} m from the USD's")
        if out:
            return out[:SHOWN]
    return out


def kit_poses(built, q: dict[str, float]) -> dict[str, np.ndarray]:
    """Each kit link's pose relative to the kit's root link (yourdfpy's joints)."""
    children = {j.child for j in built.joints}
    root = next(link.name for link in built.links if link.name not in children)
    out = {root: np.eye(4)}
    todo = [root]
    while todo:
        at = todo.pop(0)
        for j in built.joints:
            if j.parent != at:
                continue
            origin = np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float)
            motion = np.eye(4)
            axis = np.asarray((1.0, 0, 0) if j.axis is None else j.axis, dtype=float)
            value = q.get(j.name, 0.0)
            if j.type in ("revolute", "continuous"):
                motion[:3, :3] = _rodrigues(axis / np.linalg.norm(axis), value)
            elif j.type == "prismatic":
                motion[:3, 3] = axis / np.linalg.norm(axis) * value
            out[j.child] = out[at] @ origin @ motion
            todo.append(j.child)
    return out


def _rodrigues(axis: np.ndarray, angle: float) -> np.ndarray:
    x, y, z = axis
    skew = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * skew + (1 - math.cos(angle)) * skew @ skew
