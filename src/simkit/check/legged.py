"""Checks for a floating-base robot (robot.json has `floating_base`): the main MJCF survives a
passive drop onto the floor, and the control scene holds the standing pose.

Issue 6 ("Asimov legged robot"), item 5: a 1 s passive drop with no NaN; the actuated scene
holds the standing pose for 2 s with the base height drifting less than 2 cm. As MuJoCo
Menagerie does, any MuJoCo warning raised on the way fails the check.

A robot that needs active balance (robot.json `floating_base.needs_active_balance`: an
imported passive biped that cannot stand on position servos) keeps the drop and replaces the
stand with a suspended hold: the base held in place just above its standing height (its
free joint set back after every step, for the check only), the servos hold `home` within
the fixed-base hold's tolerance, with a finite state and no MuJoCo warning.
"""

from __future__ import annotations

import mujoco
import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.check.mujoco import HOLD_TOLERANCE_DEG
from simkit.model.kinematics import quat_wxyz, rpy_matrix

DROP_SECONDS = 1.0
DROP_HEIGHT = 0.05  # m the base starts above its standing height, so it really drops
HOLD_SECONDS = 2.0
HEIGHT_DRIFT_TOL = 0.02  # m (issue 6, item 5)


def _load(kit: Kit, relative: str) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(kit.path(relative)))


def standing_state(kit: Kit, model: mujoco.MjModel, lift: float = 0.0) -> mujoco.MjData:
    """MjData at robot.json's `home` pose (zeros without one): the free joint at the floating
    base's origin raised by `lift` (m), each joint by name, each servo's target at its joint."""
    base = kit.doc["floating_base"]
    data = mujoco.MjData(model)
    free = model.jnt_qposadr[model.joint(base["joint"]).id]
    data.qpos[free : free + 3] = np.add(base["origin_xyz"], (0.0, 0.0, lift))
    data.qpos[free + 3 : free + 7] = quat_wxyz(rpy_matrix(base["origin_rpy"]))
    names = [j["name"] for j in kit.joints]
    home = kit.doc.get("home") or [0.0] * len(names)
    values = dict(zip(names, home, strict=True))
    for name, q in values.items():
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = q
    for a in range(model.nu):
        if model.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_JOINT:
            joint = model.joint(int(model.actuator_trnid[a, 0])).name
            data.ctrl[a] = values.get(joint, 0.0)
    mujoco.mj_forward(model, data)
    return data


def _warnings(data: mujoco.MjData) -> list[str]:
    return [mujoco.mjtWarning(i).name for i in range(len(data.warning)) if data.warning[i].number]


def _run(
    model: mujoco.MjModel, data: mujoco.MjData, seconds: float, body: str
) -> tuple[bool, np.ndarray]:
    """Step for `seconds`; whether every state stayed finite, and the body's height per step."""
    heights = []
    for _ in range(round(seconds / model.opt.timestep)):
        mujoco.mj_step(model, data)
        if not (np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel))):
            return False, np.asarray(heights)
        heights.append(float(data.body(body).xpos[2]))
    return True, np.asarray(heights)


def check_drop(kit: Kit) -> list[Finding]:
    """The main file, servos off, dropped from just above standing height onto the floor."""
    base = kit.doc["floating_base"]["child"]
    model = _load(kit, kit.mjcf)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_ACTUATION)
    data = standing_state(kit, model, DROP_HEIGHT)
    finite, heights = _run(model, data, DROP_SECONDS, base)
    lowest = float(heights.min()) if heights.size else float("nan")
    return [
        require(
            "legged.drop.finite",
            finite,
            f"{DROP_SECONDS:g} s passive drop of {kit.mjcf}: every qpos and qvel finite"
            if finite
            else "NaN or inf in the state",
        ),
        require(
            "legged.drop.floor",
            finite and lowest > 0.0,
            f"{base} stays above the floor during the drop (lowest {lowest:.3f} m)",
        ),
        require(
            "legged.drop.warnings",
            not _warnings(data),
            f"MuJoCo warnings during the drop: {_warnings(data) or 'none'}",
        ),
    ]


def check_stand(kit: Kit) -> list[Finding]:
    """The file with the servos (the scene where the main file has none) holds `home`."""
    base = kit.doc["floating_base"]["child"]
    file = kit.doc["files"].get("mjcf_scene", kit.mjcf)
    model = _load(kit, file)
    if model.nu == 0 and kit.joints:
        return [require("legged.stand", False, f"{file} has no actuators to hold the pose")]
    # no joints at all (a rigid drone): nothing to hold, it must rest on its own
    data = standing_state(kit, model)
    start = float(data.body(base).xpos[2])
    finite, heights = _run(model, data, HOLD_SECONDS, base)
    drift = np.abs(heights - start) if finite else np.array([np.inf])
    return [
        require(
            "legged.stand.finite", finite, f"{HOLD_SECONDS:g} s standing in {file}: state finite"
        ),
        compare(
            "legged.stand.height",
            f"{base} height drift over {HOLD_SECONDS:g} s in {file} (start {start:.4f} m)",
            0.0,
            float(drift.max()),
            HEIGHT_DRIFT_TOL,
            "m",
        ),
        require(
            "legged.stand.warnings",
            not _warnings(data),
            f"MuJoCo warnings while standing: {_warnings(data) or 'none'}",
        ),
    ]


def _servo_file(kit: Kit) -> tuple[str, mujoco.MjModel]:
    """The file with the servos (the scene where the main file has none) and its model."""
    file = kit.doc["files"].get("mjcf_scene", kit.mjcf)
    return file, _load(kit, file)


def check_suspended(kit: Kit) -> list[Finding]:
    """A robot that needs active balance, its base held `DROP_HEIGHT` above its standing
    height (feet clear of the floor): the servos hold `home` (deg) for `HOLD_SECONDS`."""
    file, model = _servo_file(kit)
    if model.nu == 0 and kit.joints:
        return [require("legged.hold", False, f"{file} has no actuators to hold the pose")]
    data = standing_state(kit, model, DROP_HEIGHT)
    free = model.joint(kit.doc["floating_base"]["joint"]).id
    qa, va = model.jnt_qposadr[free], model.jnt_dofadr[free]
    held = data.qpos[qa : qa + 7].copy()
    names = [j["name"] for j in kit.joints]
    at = [model.jnt_qposadr[model.joint(n).id] for n in names]
    home = np.asarray(kit.doc.get("home") or [0.0] * len(names), dtype=float)
    finite = True
    for _ in range(round(HOLD_SECONDS / model.opt.timestep)):
        data.qpos[qa : qa + 7], data.qvel[va : va + 6] = held, 0.0  # the hold, check only
        mujoco.mj_step(model, data)
        if not (np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel))):
            finite = False
            break
    error = np.degrees(np.abs(data.qpos[at] - home)) if finite else np.full(len(names), np.inf)
    span = f"{HOLD_SECONDS:g} s suspended in {file} (base held {DROP_HEIGHT:g} m up)"
    return [
        require("legged.hold.finite", finite, f"{span}: state finite"),
        compare(
            "legged.hold.home",
            f"servos hold 'home', {span}",
            np.zeros_like(error),
            error,
            HOLD_TOLERANCE_DEG,
            "deg",
            names,
        ),
        require(
            "legged.hold.warnings",
            not _warnings(data),
            f"MuJoCo warnings while suspended: {_warnings(data) or 'none'}",
        ),
    ]


def check_legged(kit: Kit) -> list[Finding]:
    """The drop and the stand (a suspended hold where the robot needs active balance), for
    kits with a floating base only."""
    if "floating_base" not in kit.doc:
        return []
    if kit.doc["floating_base"].get("needs_active_balance"):
        return check_drop(kit) + check_suspended(kit)
    return check_drop(kit) + check_stand(kit)
