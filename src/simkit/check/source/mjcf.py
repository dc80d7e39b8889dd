"""The kit is the MJCF robot it was imported from: MuJoCo compiles both the source MJCF and
the kit's MJCF, and this compares, under the source's names (robot.json renames applied):

- joint names, types (hinge, slide; a ball as three hinges about x, y, z), axes, ranges;
- every body's mass, CoM (<= 1e-6 relative) and inertia tensor in the link frame
  (shared.inertia_close);
- the pose of every body at 100 seeded configurations (<= 1e-6 m, 1e-6 in rotation),
  relative to the robot's root;
- each joint's actuator force bound (|gear| x force range, else control range x gain);
- contact excludes: each source `<exclude>` between two kit bodies is one in the kit's MJCF,
  and each pair robot.json declares (`collision_pairs.declared`) is one in the source
  (or listed: `contact_excludes.A.B`, a pair the import excluded because it overlaps at
  the source's home, importer/fixups/overlap.py).

A difference passes only when robot.json's `source_differences` lists it (key as for a URDF:
`joints.J.axis`, `links.B.mass`, ...). The source's other files (includes, meshes) are read
beside the given MODEL.xml, else from the kit source's `NAME.source.assets/SHA256.EXT`,
each checked against its recorded digest; a source that is not the file the import read
(its digest differs: check/source/shared.py fails it) is never compiled. Frames: the kit's link
frame of a body is the body frame moved by its last hinge or ball joint's `pos` (body
axes), as the import defines it (importer/formats/mjcf/tree.py); this check computes that rule
independently.
"""

from __future__ import annotations

import hashlib
import tempfile
from pathlib import Path, PurePosixPath

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.check.source import kit_usd as source_usd
from simkit.check.source import loops as source_loops
from simkit.check.source.shared import (
    SHOWN,
    Allowed,
    inertia_close,
    unlisted_findings,
    vector_text,
)
from simkit.kitio.oneline import one_line

REL = 1e-6
ABS_LENGTH = 1e-9
#: m and rotation-matrix entries: FK agreement
FK_TOL = 1e-6
SEEDS = 100
#: mjtJoint
FREE, BALL, SLIDE, HINGE = 0, 1, 2, 3


def remake(path: Path, args: dict[str, str]) -> bytes:
    """The kept file made from the original: an MJCF is kept byte for byte."""
    return path.read_bytes()


def compare(kit: Kit, path: Path) -> list[Finding]:
    """Findings for the MJCF source at `path` against the kit's MJCF, differences
    allowed where robot.json lists them (shared.Allowed: listed keys and renames)."""
    import mujoco

    allowed = Allowed.of(kit.doc)
    recorded = kit.doc.get("source") or {}
    if hashlib.sha256(path.read_bytes()).hexdigest() != recorded.get("sha256"):
        return []  # not the file the import read (source.digest fails): never compiled
    assets = recorded.get("assets") or {}
    with tempfile.TemporaryDirectory(prefix="simkit-source-") as tmp:
        folder = Path(tmp)
        problems = _lay_out(path, assets, folder)
        if problems:
            return [require("source.digest", False, p) for p in problems[:SHOWN]]
        try:
            source = mujoco.MjSpec.from_file(str(folder / path.name)).compile()
        except Exception as exc:
            why = " ".join(str(exc).split())[:200]
            return [require("source.read", False, f"MuJoCo cannot compile the source: {why}")]
    try:
        built = mujoco.MjModel.from_xml_path(str(kit.path(kit.mjcf)))
    except Exception as exc:
        why = " ".join(str(exc).split())[:200]
        return [require("source.read", False, f"MuJoCo cannot compile the kit: {why}")]
    pairs = Pairs(source, built, allowed)
    out = unlisted_findings(
        "source.joints",
        _joints(pairs),
        f"{source.njnt} joints: names, types, axes and ranges agree",
    )
    out += unlisted_findings(
        "source.links",
        _bodies(pairs),
        f"{len(pairs.bodies)} bodies: masses, CoMs and inertias agree",
    )
    out += unlisted_findings(
        "source.fk", _fk(pairs), f"every body's pose agrees at {SEEDS} seeded configurations"
    )
    out += unlisted_findings(
        "source.actuators", _actuators(pairs), "joint actuators' force bounds agree"
    )
    declared = (kit.doc.get("collision_pairs") or {}).get("declared", [])
    excludes = _excludes(pairs, declared)
    out += unlisted_findings(
        "source.excludes", excludes, f"{source.nexclude} contact excludes agree"
    )
    out += source_loops.compare_mjcf(pairs, kit.doc)
    return out + source_usd.compare(kit, source_usd.source_of_mjcf(source), allowed)


def _lay_out(main: Path, assets: dict, folder: Path) -> list[str]:
    """The source and its recorded files in `folder` as the import read them; problems:
    a file missing or not the recorded one."""
    (folder / main.name).write_bytes(main.read_bytes())
    kept = main.parent / (main.name.removesuffix(".xml") + ".assets")
    problems = []
    for rel, digest in sorted(assets.items()):
        target = (folder / rel).resolve()
        if folder.resolve() not in target.parents or ".." in rel.split("/"):
            problems.append(f"asset '{rel}' lies outside the source's folder")
            continue
        for candidate in (main.parent / rel, kept / f"{digest}{PurePosixPath(rel).suffix.lower()}"):
            if candidate.is_file() and hashlib.sha256(candidate.read_bytes()).hexdigest() == digest:
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(candidate.read_bytes())
                break
        else:
            problems.append(
                f"source file '{rel}' is missing or not the one the import read "
                f"(sha256 {digest[:12]}...)"
            )
    return problems


class Pairs:
    """The two compiled models and the source -> kit pairing of joints and bodies."""

    def __init__(self, source, kit, allowed) -> None:
        self.source, self.kit, self.allowed = source, kit, allowed
        tops = {int(source.body_rootid[source.jnt_bodyid[j]]) for j in range(source.njnt)}
        self.root = min(tops) if tops else 1
        self.bodies = [b for b in range(1, source.nbody) if source.body_rootid[b] == self.root]
        self.offset, self.kit_offset = _offsets(source), _offsets(kit)

    def kit_id(self, kind: str, name: str) -> int:
        """The kit's body or joint id of source element `name` (-1: none)."""
        import mujoco

        table = self.allowed.links if kind == "body" else self.allowed.joints
        new = table.get(one_line(name), name)
        obj = mujoco.mjtObj.mjOBJ_BODY if kind == "body" else mujoco.mjtObj.mjOBJ_JOINT
        return mujoco.mj_name2id(self.kit, obj, new)

    def kit_site(self, name: str) -> int:
        """The kit's site (a frame) of a massless source body `name` (-1: none)."""
        import mujoco

        new = self.allowed.links.get(one_line(name), name)
        return mujoco.mj_name2id(self.kit, mujoco.mjtObj.mjOBJ_SITE, new)

    def listed(self, key: str) -> bool:
        return key in self.allowed.keys


def _offsets(model) -> np.ndarray:
    """Each body's link frame in its body frame (m): its last hinge or ball joint's `pos`
    (zero in a kit, whose joints turn about their link's origin)."""
    out = np.zeros((model.nbody, 3))
    for j in range(model.njnt):
        if model.jnt_type[j] in (HINGE, BALL):
            out[model.jnt_bodyid[j]] = model.jnt_pos[j]
    return out


def _name(model, kind: str, i: int) -> str:
    return getattr(model, kind)(i).name or f"{kind}{i}"


def _joints(p: Pairs) -> list[str]:
    """Each source joint (not the free root): in the kit, same type, axis and range."""
    out: list[str] = []
    s, k = p.source, p.kit
    for j in range(s.njnt):
        kind, name = int(s.jnt_type[j]), _name(s, "jnt", j)
        if kind == FREE:
            continue
        if kind == BALL:
            for part, axis in (
                (f"{name}_x", (1, 0, 0)),
                (f"{name}_y", (0, 1, 0)),
                (name, (0, 0, 1)),
            ):
                kj = p.kit_id("joint", part)
                if (
                    kj < 0
                    or k.jnt_type[kj] != HINGE
                    or not np.allclose(k.jnt_axis[kj], axis, atol=REL)
                ):
                    out.append(
                        f"joint '{name}': a ball, not three hinges "
                        f"{name}_x, {name}_y, {name} about x, y, z"
                    )
                    break
            continue
        kj = p.kit_id("joint", name)
        if kj < 0:
            if not p.listed(f"joints.{name}"):
                out.append(f"joint '{name}' is missing from the kit")
            continue
        key = f"joints.{name}"
        if k.jnt_type[kj] != kind and not p.listed(f"{key}.type"):
            out.append(
                f"joint '{name}': type {kind} in the source, {int(k.jnt_type[kj])} in the kit"
            )
        if not np.allclose(s.jnt_axis[j], k.jnt_axis[kj], atol=REL) and not p.listed(f"{key}.axis"):
            out.append(
                f"joint '{name}': axis {vector_text(s.jnt_axis[j])} in the source, "
                f"{vector_text(k.jnt_axis[kj])} in the kit"
            )
        if s.jnt_limited[j]:
            for side, attr in ((0, "lower"), (1, "upper")):
                a, b = s.jnt_range[j][side], k.jnt_range[kj][side]
                if not p.listed(f"{key}.{attr}") and (
                    not k.jnt_limited[kj] or abs(a - b) > REL * abs(a) + ABS_LENGTH
                ):
                    out.append(f"joint '{name}': {attr} {a:.9g} in the source, {b:.9g} in the kit")
        elif k.jnt_limited[kj] and not p.listed(f"{key}.lower"):
            out.append(f"joint '{name}': unlimited in the source, limited in the kit")
    return out


def _mass_properties(model, body: int, offset) -> tuple[float, np.ndarray, np.ndarray]:
    """(kg, CoM m, inertia about the CoM kg m^2), in the body's link frame."""
    w, x, y, z = model.body_iquat[body]
    rot = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip
    tensor = rot @ np.diag(model.body_inertia[body]) @ rot.T
    return float(model.body_mass[body]), model.body_ipos[body] - offset, tensor


def _bodies(p: Pairs) -> list[str]:
    """Each source body of the robot: in the kit, same mass, CoM and inertia."""
    out: list[str] = []
    for b in p.bodies:
        name = _name(p.source, "body", b)
        kb = p.kit_id("body", name)
        if kb < 0:
            massless = p.source.body_mass[b] == 0 and (b == p.root or p.kit_site(name) >= 0)
            if not p.listed(f"links.{name}") and not massless:  # the kit's world or a frame
                out.append(f"link '{name}' is missing from the kit")
            continue
        m0, c0, i0 = _mass_properties(p.source, b, p.offset[b])
        m1, c1, i1 = _mass_properties(p.kit, kb, p.kit_offset[kb])
        key = f"links.{name}"
        if abs(m0 - m1) > REL * m0 and not p.listed(f"{key}.mass"):
            out.append(f"link '{name}': mass {m0:.9g} kg in the source, {m1:.9g} in the kit")
        if m0 == 0:
            continue  # a massless body has no CoM or inertia
        if np.max(np.abs(c0 - c1)) > REL * np.max(np.abs(c0)) + ABS_LENGTH and not p.listed(
            f"{key}.com"
        ):
            out.append(
                f"link '{name}': CoM {vector_text(c0)}"
                f" m in the source, {vector_text(c1)} in the kit"
            )
        if not inertia_close(i0, i1) and not p.listed(f"{key}.inertia"):
            out.append(
                f"link '{name}': inertia {vector_text(np.diag(i0))} kg m^2 in the source, "
                f"{vector_text(np.diag(i1))} in the kit"
            )
    return out


def _configurations(p: Pairs, rng) -> tuple[np.ndarray, np.ndarray]:
    """One seeded configuration as (source qpos, kit qpos): each hinge or slide drawn in
    its source range (else +-pi rad, +-0.1 m), a ball as three angles about x, y, z."""
    import mujoco

    s, k = p.source, p.kit
    qs, qk = s.qpos0.copy(), k.qpos0.copy()
    for j in range(s.njnt):
        kind, name, at = int(s.jnt_type[j]), _name(s, "jnt", j), int(s.jnt_qposadr[j])
        if kind == BALL:
            angles = rng.uniform(-np.pi, np.pi, 3)
            quat, part = np.array([1.0, 0, 0, 0]), np.zeros(4)
            for axis, angle, suffix in zip(np.eye(3), angles, ("_x", "_y", ""), strict=True):
                mujoco.mju_axisAngle2Quat(part, axis, angle)
                mujoco.mju_mulQuat(quat, quat.copy(), part)
                kj = p.kit_id("joint", name + suffix)
                if kj >= 0:
                    qk[k.jnt_qposadr[kj]] = angle
            qs[at : at + 4] = quat
        elif kind in (HINGE, SLIDE):
            span = np.pi if kind == HINGE else 0.1
            low, high = s.jnt_range[j] if s.jnt_limited[j] else (-span, span)
            value = rng.uniform(low, high)
            qs[at] = value
            kj = p.kit_id("joint", name)
            if kj >= 0:
                qk[k.jnt_qposadr[kj]] = value
    return qs, qk


def _fk(p: Pairs) -> list[str]:
    """Every source body's link frame relative to the robot's root link (the world where
    the root is jointed to it), kit against source."""
    import mujoco

    s, k = p.source, p.kit
    root_name = _name(s, "body", p.root)
    moves = s.body_jntnum[p.root] > 0 and s.jnt_type[s.body_jntadr[p.root]] != FREE
    ref_s, ref_k = (0, 0) if moves else (p.root, p.kit_id("body", root_name))
    if ref_k < 0 and s.body_mass[p.root] == 0:
        ref_k = 0  # a massless root is the kit's world body
    if ref_k < 0:
        return [f"the root body '{root_name}' is missing from the kit"]
    pairs = [(b, p.kit_id("body", _name(s, "body", b))) for b in p.bodies]
    sites = [(b, p.kit_site(_name(s, "body", b))) for b, kb in pairs if kb < 0]
    pairs = [(b, kb) for b, kb in pairs if kb >= 0]
    ds, dk = mujoco.MjData(s), mujoco.MjData(k)
    rng = np.random.default_rng(0)
    worst: dict[str, float] = {}
    for _ in range(SEEDS):
        ds.qpos[:], dk.qpos[:] = _configurations(p, rng)
        mujoco.mj_kinematics(s, ds)
        mujoco.mj_kinematics(k, dk)
        rs, rk = ds.xmat[ref_s].reshape(3, 3), dk.xmat[ref_k].reshape(3, 3)
        os_ = ds.xpos[ref_s] + rs @ p.offset[ref_s]
        ok = dk.xpos[ref_k] + rk @ p.kit_offset[ref_k]
        kit_poses = [(b, dk.xpos[kb] + dk.xmat[kb].reshape(3, 3) @ p.kit_offset[kb],
                      dk.xmat[kb].reshape(3, 3)) for b, kb in pairs]  # fmt: skip
        kit_poses += [
            (b, dk.site_xpos[k], dk.site_xmat[k].reshape(3, 3)) for b, k in sites if k >= 0
        ]
        for b, kit_x, mk in kit_poses:
            ms = ds.xmat[b].reshape(3, 3)
            xs = rs.T @ (ds.xpos[b] + ms @ p.offset[b] - os_)
            xk = rk.T @ (kit_x - ok)
            err = max(float(np.max(np.abs(xs - xk))), float(np.max(np.abs(rs.T @ ms - rk.T @ mk))))
            if err > FK_TOL:
                name = _name(s, "body", b)
                worst[name] = max(worst.get(name, 0.0), err)
    return [
        f"link '{n}': pose off by up to {e:.3g} m (or rotation) at seeded configurations"
        for n, e in worst.items()
    ]


def bound(model, joint: int) -> float | None:
    """The joint's actuator force bound (N m or N), None when unbounded or unactuated."""
    values = []
    for a in range(model.nu):
        if model.actuator_trntype[a] > 1 or model.actuator_trnid[a][0] != joint:
            continue
        gear = abs(float(model.actuator_gear[a][0]))
        if model.actuator_forcelimited[a]:
            values.append(gear * float(np.max(np.abs(model.actuator_forcerange[a]))))
        elif model.actuator_ctrllimited[a] and not (
            model.actuator_gaintype[a] or model.actuator_biastype[a] or model.actuator_dyntype[a]
        ):
            scale = abs(float(model.actuator_gainprm[a][0]))
            values.append(gear * scale * float(np.max(np.abs(model.actuator_ctrlrange[a]))))
        else:
            return None
    total = sum(values) if values else None
    if model.jnt_actfrclimited[joint]:
        cap = float(np.max(np.abs(model.jnt_actfrcrange[joint])))
        total = cap if total is None else min(total, cap)
    return total


def _actuators(p: Pairs) -> list[str]:
    """Each actuated source joint's force bound equals the kit's servo force range."""
    out = []
    for j in range(p.source.njnt):
        name = _name(p.source, "jnt", j)
        want = bound(p.source, j)
        kj = p.kit_id("joint", name)
        if want is None or kj < 0 or p.listed(f"joints.{name}.effort_peak"):
            continue
        got = bound(p.kit, kj)
        if got is None or abs(got - want) > REL * want:
            out.append(
                f"joint '{name}': actuator force bound {want:.9g} in the source, {got} in the kit"
            )
    return out


def _excluded(model, sig: int) -> frozenset:
    """The two body names of a compiled `<exclude>` (its signature: body ids, 16 bits each)."""
    return frozenset(_name(model, "body", i) for i in (sig >> 16, sig & 0xFFFF))


def _excludes(p: Pairs, declared: list) -> list[str]:
    """Each source `<exclude>` whose two bodies the kit has is excluded in the kit's MJCF too
    (unless listed: `contact_excludes.NAME`), and each pair robot.json declares excluded is
    one the source excludes: the kit may filter no contact the source keeps."""
    s, k = p.source, p.kit
    kit_pairs = {_excluded(k, int(sig)) for sig in k.exclude_signature}
    source_pairs, out = set(), []
    for e in range(s.nexclude):
        a, b = sorted(_excluded(s, int(s.exclude_signature[e])))
        ids = (p.kit_id("body", a), p.kit_id("body", b))
        if min(ids) < 0:
            continue  # no kit body (a body outside the robot's tree: listed)
        pair = frozenset(_name(k, "body", i) for i in ids)
        source_pairs.add(pair)
        if pair not in kit_pairs and not p.listed(f"contact_excludes.{_name(s, 'exclude', e)}"):
            out.append(f"bodies '{a}' and '{b}': excluded from contact in the source, not the kit")
    for a, b in declared:
        if frozenset((a, b)) not in source_pairs and not p.listed(f"contact_excludes.{a}.{b}"):
            out.append(f"links '{a}' and '{b}': declared excluded, not excluded in the source")
    return out
