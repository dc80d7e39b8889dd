"""Check the written USD: schema validation, UsdPhysics' own parser, and agreement with the MJCF
loaded in MuJoCo (masses, CoM, inertia, joint frames, axes, limits, drives, colliders and the
tool pose at random configurations composed from the USD joints)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.check.loops import usd_findings as usd_loop_findings
from simkit.check.mujoco import load_control_mjcf
from simkit.check.readers.usd import (
    UsdJoint,
    UsdKinematics,
    joints_from_parser,
    joints_from_schemas,
    matrix,
    parse_physics,
    prim_name,
    validate,
)
from simkit.check.usd_collision import collision_findings
from simkit.check.usd_fk import fk_findings
from simkit.check.usd_layout import (
    VARIANT_SET,
    asset_findings,
    geometry_only_findings,
    layer_findings,
    normals_findings,
    robot_schema_findings,
    thumbnail_findings,
)
from simkit.check.usd_mimic import follower_servo, followers
from simkit.check.usd_mjc import MJC_VARIANT, mjc_findings
from simkit.kitio import layout

#: USD stores masses, inertia, joint frames and drive gains as 32-bit floats (about 7
#: significant digits): relative tolerance for values compared one by one.
FLOAT32_REL = 1e-6


def usd_path(kit: Kit) -> Path | None:
    """The kit's USD file: robot.json `files.usd` if given, else `usd/NAME.usda` or `.usdc`."""
    named = kit.doc.get("files", {}).get("usd")
    for rel in ([named] if named else []) + [layout.usd(kit.name), layout.usd(kit.name, True)]:
        if kit.path(rel).is_file():
            return kit.path(rel)
    return None


def _tol(values) -> float:
    """FLOAT32_REL of the largest magnitude compared (float32 storage in USD)."""
    arr = np.abs(np.asarray(values, dtype=float))
    return FLOAT32_REL * max(float(arr.max()) if arr.size else 0.0, 1e-9)


def _mj_tensor(mj: mujoco.MjModel, body: int) -> np.ndarray:
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, mj.body_iquat[body])
    rot = rot.reshape(3, 3)
    return rot @ np.diag(mj.body_inertia[body]) @ rot.T


def _mass_findings(stage, mj, links: dict[str, str]) -> list[Finding]:
    """Per-link MassAPI (inertia rebuilt from diagonalInertia and principalAxes) vs MJCF."""
    from pxr import UsdPhysics

    exp: dict[str, list] = {"mass": [], "com": [], "inertia": []}
    act: dict[str, list] = {"mass": [], "com": [], "inertia": []}
    for name, path in links.items():
        api = UsdPhysics.MassAPI(stage.GetPrimAtPath(path))
        body = mj.body(name).id
        exp["mass"].append(mj.body_mass[body])
        exp["com"].append(mj.body_ipos[body])
        exp["inertia"].append(_mj_tensor(mj, body))
        act["mass"].append(api.GetMassAttr().Get())
        act["com"].append(list(api.GetCenterOfMassAttr().Get()))
        rot = matrix((0, 0, 0), api.GetPrincipalAxesAttr().Get())[:3, :3]
        act["inertia"].append(rot @ np.diag(list(api.GetDiagonalInertiaAttr().Get())) @ rot.T)
    return [
        compare(
            "usd.mass",
            "per-link MassAPI mass vs MJCF",
            exp["mass"],
            act["mass"],
            _tol(exp["mass"]),
            "kg",
            list(links),
        ),
        compare(
            "usd.com",
            "per-link MassAPI centerOfMass vs MJCF (link frame)",
            exp["com"],
            act["com"],
            max(_tol(exp["com"]), 1e-7),
            "m",
            list(links),
        ),
        compare(
            "usd.inertia",
            "per-link inertia tensor from diagonalInertia and principalAxes vs MJCF (link axes)",
            exp["inertia"],
            act["inertia"],
            _tol(exp["inertia"]),
            "kg m^2",
            list(links),
        ),
    ]


def _mj_local(mj, body: int) -> np.ndarray:
    """T_parent_body of an MJCF body (its pos/quat)."""
    out, rot = np.eye(4), np.zeros(9)
    mujoco.mju_quat2Mat(rot, mj.body_quat[body])
    out[:3, :3], out[:3, 3] = rot.reshape(3, 3), mj.body_pos[body]
    return out


def _to_welded(mj, child: int, parent: str, joint: UsdJoint) -> bool:
    """A fixed USD joint from a body welded to the world to an MJCF child of the world: both
    formats hold the child fixed to the world (emit/usd.py fixes a massless root frame's other
    links to its first one, so that one articulation holds them)."""
    if joint.kind != "fixed" or int(mj.body_parentid[child]) != 0 or parent == "world":
        return False
    body = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, parent)
    return body > 0 and int(mj.body_weldid[body]) == 0


def _joint_findings(mj, kit: Kit, joints: list[UsdJoint], names: dict[str, str]) -> list[Finding]:
    """Every USD joint joins the MJCF parent and child bodies at the MJCF body frame; movable
    joints have the MJCF axis, limits and servo. `names`: USD path -> link name."""
    wrong, frames_exp, frames_act = [], [], []
    for j in joints:
        child = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, names.get(j.body1, "?"))
        parent = names.get(j.body0, "world")
        if child >= 0 and _to_welded(mj, child, parent, j):
            continue  # fixed to the world in both; the FK checks its frame
        if child < 0 or mj.body(int(mj.body_parentid[child])).name != parent:
            wrong.append(j.path)
        elif parent != "world":  # a joint from the world: the FK checks its frame
            frames_exp.append(_mj_local(mj, child))
            frames_act.append(j.pose0 @ np.linalg.inv(j.pose1))
    by_name = {j.path.rsplit("/", 1)[-1]: j for j in joints}
    missing = [d["name"] for d in kit.joints if prim_name(d["name"]) not in by_name]
    findings = [
        require(
            "usd.joint_bodies",
            not wrong and not missing,
            f"every joint joins the MJCF parent and child (wrong: {wrong}; missing: {missing})",
        ),
        compare(
            "usd.joint_frames",
            "joint localPose0 * inv(localPose1) vs MJCF body pos/quat",
            frames_exp,
            frames_act,
            2e-7,
            "m or 1",
        ),
    ]
    axes_exp, axes_act, lim_exp, lim_act, drv_exp, drv_act, odd = [], [], [], [], [], [], []
    actuated = {
        int(mj.actuator_trnid[a, 0]): a
        for a in range(mj.nu)
        if mj.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT
    }
    follows = followers(mj)
    for doc in kit.joints:
        usd = by_name.get(prim_name(doc["name"]))
        if usd is None:
            continue
        jid = mj.joint(doc["name"]).id
        axes_exp.append(np.concatenate([mj.jnt_axis[jid], mj.jnt_pos[jid]]))
        axes_act.append(np.concatenate([usd.pose1[:3, :3] @ usd.axis, usd.pose1[:3, 3]]))
        act, aim, follower = actuated.get(jid), 0.0, follower_servo(mj, jid, follows, actuated)
        if follower is not None:  # a slide follower: driven by its leader's servo
            act, aim = follower
        dof, qadr = int(mj.jnt_dofadr[jid]), int(mj.jnt_qposadr[jid])
        # a joint without a servo but with MJCF stiffness or damping is a passive spring-damper:
        # a force drive aimed at springref (qpos_spring) with no force limit; a mimic follower
        # has none
        spring = act is None and jid not in follows
        spring = spring and bool(mj.jnt_stiffness[jid] or mj.dof_damping[dof])
        if (
            bool(mj.jnt_limited[jid]) != (usd.limit is not None)
            or (act is None and not spring) != (usd.drive is None)
            or (spring and usd.drive is not None and math.isfinite(usd.drive[2]))
        ):
            odd.append(doc["name"])
            continue
        unit = math.radians if usd.kind == "revolute" else float  # USD: degrees
        if usd.limit is not None:
            lim_exp.append(mj.jnt_range[jid])
            lim_act.append([unit(v) for v in usd.limit])
        if usd.drive is not None:
            per = 180.0 / math.pi if usd.kind == "revolute" else 1.0  # USD: gains per degree
            if act is not None:
                gains = [mj.actuator_gainprm[act, 0], -mj.actuator_biasprm[act, 2]]
                max_force, target = mj.actuator_forcerange[act, 1], aim
            else:
                gains = [mj.jnt_stiffness[jid], mj.dof_damping[dof]]
                max_force, target = math.inf, mj.qpos_spring[qadr]  # no limit: not compared
            drv_exp.append([*gains, max_force, target])
            drv_act.append(
                [usd.drive[0] * per, usd.drive[1] * per, usd.drive[2], unit(usd.drive[3])]
            )
    findings += [
        require(
            "usd.limits_drives",
            not odd,
            f"limits and drives where the MJCF has a range, a servo or a passive spring-damper "
            f"(differ: {odd})",
        ),
        compare(
            "usd.axes",
            "joint axis and anchor in the child frame vs MJCF",
            axes_exp,
            axes_act,
            2e-7,
            "1 or m",
        ),
        compare(
            "usd.limits",
            "joint limits (USD degrees) vs MJCF range",
            lim_exp,
            lim_act,
            1e-5 * max(1.0, float(np.abs(lim_exp).max(initial=0))),
            "rad or m",
        ),
    ]
    for i, (what, unit) in enumerate(
        (
            ("stiffness", "N m/rad"),
            ("damping", "N m s/rad"),
            ("maxForce", "N m"),
            ("targetPosition", "rad"),
        )
    ):
        rows = [(e[i], a[i]) for e, a in zip(drv_exp, drv_act, strict=True) if math.isfinite(e[i])]
        exp = [e for e, _ in rows]
        findings.append(
            compare(
                f"usd.drive.{what}",
                f"DriveAPI {what} vs MJCF servo or passive spring-damper",
                exp,
                [a for _, a in rows],
                max(_tol(exp), 1e-9),
                unit,
            )
        )
    return findings


def _open(kit: Kit):
    """(stage, entry path, findings so far): the composed stage of the entry layer, every
    payload loaded, with the usd-core validators' and the stage metadata's findings."""
    from pxr import Usd, UsdGeom, UsdPhysics

    path = usd_path(kit)
    if path is None:
        return None, None, [require("usd.present", False, f"no {layout.usd(kit.name)} (or .usdc)")]
    rel = path.relative_to(kit.root).as_posix()
    try:
        stage = Usd.Stage.Open(str(path), Usd.Stage.LoadAll)
    except Exception as exc:  # pxr raises Tf.ErrorException with the parser's message
        return None, path, [require("usd.open", False, f"{rel}: {exc}")]
    broken = [
        " ".join(str(e).replace(f"{path.parent}/", "").split())[:240]
        for e in stage.GetCompositionErrors()
    ]
    if broken:  # a layer that does not open or parse, an arc to nothing
        return stage, path, [require("usd.open", False, f"{rel}: {'; '.join(broken[:3])}")]
    errors, warns = validate(stage)
    top = stage.GetDefaultPrim()
    meta = (
        UsdGeom.GetStageUpAxis(stage),
        UsdGeom.GetStageMetersPerUnit(stage),
        UsdPhysics.GetStageKilogramsPerUnit(stage),
    )
    return (
        stage,
        path,
        [
            require(
                "usd.validate",
                not errors,
                f"{rel}: usd-core validators found "
                f"{len(errors)} error(s), {warns} warning(s){': ' if errors else ''}"
                f"{'; '.join(errors[:3])}",
            ),
            require(
                "usd.stage",
                bool(top) and meta == ("Z", 1.0, 1.0),
                f"defaultPrim {top.GetPath() if top else None}, upAxis, metersPerUnit, "
                f"kilogramsPerUnit {meta} (Z, 1, 1)",
            ),
        ],
    )


def check_usd(kit: Kit) -> list[Finding]:
    """Validate the USD, check its layout, and compare the composed stage with the MJCF in
    MuJoCo in every physics variant (names `usd.X` for the default variant, `usd.VARIANT.X`
    for the others; the "none" variant must hold no physics)."""
    stage, path, findings = _open(kit)
    top = stage.GetDefaultPrim() if stage is not None else None
    if not top or not all(f.ok for f in findings if f.check == "usd.open"):
        return findings
    findings += layer_findings(stage) + normals_findings(stage) + thumbnail_findings(path)
    if path.parent.name == "usd":  # the kit's entry point: the Isaac asset is beside it
        asset = path.parent / path.stem / path.name
        findings += asset_findings(path, asset)
    variants = top.GetVariantSet(VARIANT_SET)
    names = variants.GetVariantNames() if top.HasVariantSets() else []
    if not names:  # a one-layer stage (kits before the Isaac asset structure)
        return findings + _physics(kit, stage, top)
    default = variants.GetVariantSelection()
    for name in names:
        _select(stage, top, name)
        if name == "none":
            findings += geometry_only_findings(stage)
            continue
        found = _physics(kit, stage, top)
        if name == MJC_VARIANT:
            found += mjc_findings(stage, top, load_control_mjcf(kit))
        if name != default:
            found = [replace(f, check=f"usd.{name}.{f.check[4:]}") for f in found]
        findings += found
    _select(stage, top, default)
    return findings


def _select(stage, top, variant: str) -> None:
    """Select a physics variant in the session layer (the files stay as written)."""
    from pxr import Usd

    with Usd.EditContext(stage, stage.GetSessionLayer()):
        top.GetVariantSet(VARIANT_SET).SetVariantSelection(variant)


def _physics(kit: Kit, stage, top) -> list[Finding]:
    """Rigid bodies, the articulation, masses, joints, colliders, the robot schema and the
    FK of the composed stage vs the MJCF."""
    from pxr import Usd, UsdGeom, UsdPhysics

    root = str(top.GetPath())
    links = {link["name"]: f"{root}/{prim_name(link['name'])}" for link in kit.doc["links"]}
    missing = [
        n for n, p in links.items() if not stage.GetPrimAtPath(p).HasAPI(UsdPhysics.RigidBodyAPI)
    ]
    findings = [require("usd.bodies", not missing, f"a rigid body per link (missing {missing})")]
    if missing:
        return findings
    parsed = parse_physics(stage)
    if parsed is not None:
        joints = joints_from_parser(parsed)
        findings.append(_articulation(kit, parsed, joints, links))
    else:
        joints = joints_from_schemas(stage)
    mj = load_control_mjcf(kit)  # the servos the USD drives mirror
    findings += _mass_findings(stage, mj, links)
    findings += _joint_findings(mj, kit, joints, {p: n for n, p in links.items()})
    if top.GetRelationship("isaac:physics:robotLinks"):
        findings += robot_schema_findings(stage, top, links, [j.path for j in joints])
    if parsed is not None:
        findings += collision_findings(parsed, mj, links)
    findings += usd_loop_findings(kit, stage, root)
    xforms: dict[str, str] = {}
    for prim in Usd.PrimRange(top):
        if prim.IsA(UsdGeom.Xform):
            xforms.setdefault(prim.GetName(), str(prim.GetPath()))
    paths = {
        name: xforms[prim_name(name)]
        for name in kit.doc.get("frames", {})
        if prim_name(name) in xforms
    }
    paths.update(links)
    paths.update({n: root for n, f in kit.doc.get("frames", {}).items() if "parent" not in f})
    try:
        findings += fk_findings(kit, mj, UsdKinematics(stage, joints), paths)
    except (ValueError, KeyError) as exc:  # joints that do not form a tree, unknown bodies
        findings.append(require("usd.fk", False, f"cannot compose the USD joints: {exc}"))
    return findings


def _articulation(kit: Kit, parsed: dict, joints: list[UsdJoint], links: dict) -> Finding:
    """Exactly one articulation, holding every link a joint moves."""
    from pxr import UsdPhysics

    arts = parsed.get(UsdPhysics.ObjectType.Articulation, ([], []))[1]
    held = {str(b) for a in arts for b in a.articulatedBodies}
    moved = {str(p) for a in arts for p in a.articulatedJoints}
    held |= {b for j in joints if j.path in moved for b in (j.body0, j.body1)}
    # the parser may leave out a body whose only joint is the articulated one from the world
    # (a hinged cube); a rigid robot (a drone's frame and props, fixed or floating) has no
    # joint to articulate
    need = {links[n] for n in kit.moved_links() if n in links}
    return require(
        "usd.articulation",
        (len(arts) == 1 and need <= held) or (not need and len(arts) <= 1),
        f"UsdPhysics parser: {len(arts)} articulation(s) holding every link a joint "
        f"moves ({len(need)} of {len(links)})",
    )
