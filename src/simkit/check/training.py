"""Check `training/` (issue 41): every value the Playground and mjlab files hold, read back with
`ast` (without importing either framework), against the GPU scene compiled in MuJoCo, and the
Isaac Lab config against the composed USD stage (check/training_usd.py).

Why: the point of generating these files is that no gain, limit or pose is copied by hand; a
file edited after the build, or an emitter that drifts from the scene, fails here.
"""

from __future__ import annotations

import ast
import math
from pathlib import Path

import mujoco
import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.kitio import layout

#: relative tolerance on values written with 10 significant digits (kitio/fmt.num)
RELATIVE = 1e-9
#: a foot collider is within this of the floor at home (m; derive/gpu_scene.py's margin)
FOOT_MARGIN = 0.01
#: sensor role -> MuJoCo sensor type
ROLE_TYPES = {
    "gyro": mujoco.mjtSensor.mjSENS_GYRO,
    "local_linvel": mujoco.mjtSensor.mjSENS_VELOCIMETER,
    "orientation": mujoco.mjtSensor.mjSENS_FRAMEQUAT,
    "upvector": mujoco.mjtSensor.mjSENS_FRAMEZAXIS,
}


def constants(path: Path) -> dict:
    """Module-level `NAME = literal` assignments of a Python file, read with `ast` only."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=path.name)
    out: dict = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1:
            target = node.targets[0]
            if isinstance(target, ast.Name):
                try:
                    out[target.id] = ast.literal_eval(node.value)
                except ValueError:
                    continue
    return out


def _close(expected: float | None, actual: float | None) -> bool:
    if expected is None or actual is None:
        return expected is None and actual is None
    return abs(expected - actual) <= RELATIVE * max(1.0, abs(expected))


def servo_table(model: mujoco.MjModel, velocities: dict[str, float | None]) -> dict[str, dict]:
    """The scene's servos as the files write them (see emit/training.py `actuators`)."""
    out: dict[str, dict] = {}
    for a in range(model.nu):
        joint = int(model.actuator_trnid[a, 0])
        limited = bool(model.jnt_limited[joint])
        out[model.actuator(a).name] = {
            "kp": float(model.actuator_gainprm[a, 0]),
            "kv": float(-model.actuator_biasprm[a, 2]),
            "effort": float(model.actuator_forcerange[a, 1]),
            "range": tuple(float(v) for v in model.jnt_range[joint]) if limited else None,
            "velocity": velocities.get(model.joint(joint).name),
            "armature": float(model.dof_armature[model.jnt_dofadr[joint]]),
        }
    return out


def _servo_findings(name: str, written: dict, scene: dict[str, dict]) -> list[Finding]:
    wrong = []
    for joint, expected in scene.items():
        got = written.get(joint)
        if got is None:
            wrong.append(f"{joint}: missing")
            continue
        for key, value in expected.items():
            if key == "range":
                same = (value is None) == (got.get(key) is None) and (
                    value is None or all(map(_close, value, got[key]))
                )
            else:
                same = _close(value, got.get(key))
            if not same:
                wrong.append(f"{joint}.{key}: {got.get(key)} (scene {value})")
    extra = sorted(set(written) - set(scene))
    order = list(written) == list(scene)
    return [
        require(
            f"training.{name}.servos",
            not wrong and not extra and order,
            f"{name}: kp, kv, effort, range, velocity and armature of every servo vs the GPU "
            f"scene and robot.json"
            + (f" (differ: {wrong[:4]})" if wrong else "")
            + (f" (not in the scene: {extra})" if extra else "")
            + ("" if order else " (not in the scene's actuator order)"),
        )
    ]


def _scene(kit: Kit, values: dict, name: str) -> tuple[mujoco.MjModel | None, list[Finding]]:
    expected = layout.mjcf_mjx(kit.name)
    ok = values.get("SCENE") == expected and kit.path(expected).is_file()
    found = [require(f"training.{name}.scene", ok, f"SCENE {values.get('SCENE')!r} is {expected}")]
    return (mujoco.MjModel.from_xml_path(str(kit.path(expected))) if ok else None), found


def _home(model: mujoco.MjModel, values: dict) -> list[Finding]:
    name = values.get("HOME")
    try:
        key = model.key(name)
    except (KeyError, TypeError):
        return [
            require("training.playground.home", False, f"no keyframe {name!r} in the GPU scene")
        ]
    return [
        compare(
            "training.playground.home",
            f"HOME_QPOS, HOME_CTRL vs the GPU scene's keyframe {name!r}",
            np.concatenate([key.qpos, key.ctrl]),
            np.concatenate([values.get("HOME_QPOS", ()), values.get("HOME_CTRL", ())]),
            1e-9,
            "rad or m",
        )
    ]


def _sensors(kit: Kit, model: mujoco.MjModel, values: dict) -> list[Finding]:
    roles = values.get("SENSORS", {})
    wrong = []
    for role, name in roles.items():
        sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, name)
        if sid < 0 or model.sensor_type[sid] != ROLE_TYPES.get(role):
            wrong.append(f"{role}: {name}")
    named = [s["name"] for s in kit.doc.get("sensors") or []]
    complete = not values.get("FLOATING") or (
        {"gyro", "local_linvel"} <= set(roles) and bool({"orientation", "upvector"} & set(roles))
    )
    return [
        require(
            "training.playground.sensors",
            not wrong and complete and list(values.get("NAMED_SENSORS", ())) == named,
            "base sensors are the GPU scene's, of their role's type, and a floating base has "
            f"gyro, linear velocity and orientation (wrong: {wrong}; complete: {complete}); "
            "NAMED_SENSORS are robot.json's",
        )
    ]


def _feet(model: mujoco.MjModel, values: dict) -> list[Finding]:
    feet = list(values.get("FEET", ()))
    if not feet:
        ok = not values.get("FLOATING") or model.npair == 0
        return [
            require(
                "training.playground.feet", ok, "a floating base with floor pairs names its feet"
            )
        ]
    floors = {int(a) for a, b in zip(model.pair_geom1, model.pair_geom2, strict=True)}
    floors = {g for g in floors if model.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE}
    model.pair_margin[:] = FOOT_MARGIN  # a contact within the margin counts as touching
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key(values["HOME"]).id)
    mujoco.mj_forward(model, data)
    touching = {
        model.geom(int(b if a in floors else a)).name
        for a, b in data.contact.geom[: data.ncon]
        if a in floors or b in floors
    }
    wrong = sorted(set(feet) - touching)
    return [
        require(
            "training.playground.feet",
            not wrong,
            f"FEET are floor-pair colliders within {FOOT_MARGIN} m of the floor at home "
            f"(not: {wrong})",
        )
    ]


def _playground(kit: Kit, velocities: dict) -> list[Finding]:
    values = constants(kit.path(layout.PLAYGROUND_ENV))
    model, found = _scene(kit, values, "playground")
    if model is None:
        return found
    found += [
        require("training.playground.kit", values.get("KIT") == kit.name, "KIT is the kit"),
        require(
            "training.playground.floating",
            values.get("FLOATING") == bool(kit.doc.get("floating_base")),
            "FLOATING as robot.json",
        ),
        compare(
            "training.playground.timestep",
            "TIMESTEP vs the GPU scene",
            [model.opt.timestep],
            [values.get("TIMESTEP", math.nan)],
            1e-12,
            "s",
        ),
    ]
    found += _servo_findings(
        "playground", values.get("ACTUATORS", {}), servo_table(model, velocities)
    )
    return found + _home(model, values) + _sensors(kit, model, values) + _feet(model, values)


def _mjlab(kit: Kit, velocities: dict) -> list[Finding]:
    values = constants(kit.path(layout.MJLAB_CFG))
    model, found = _scene(kit, values, "mjlab")
    if model is None:
        return found
    found += _servo_findings("mjlab", values.get("ACTUATORS", {}), servo_table(model, velocities))
    key = model.key(values.get("HOME", "")) if values.get("HOME") else None
    if key is None:
        return [*found, require("training.mjlab.home", False, "no HOME keyframe")]
    joints = values.get("HOME_JOINTS", {})
    exp, act = [], []
    for j in range(model.njnt):
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            adr = model.jnt_qposadr[j]
            exp += list(key.qpos[adr : adr + 7])
            act += [*values.get("BASE_POS", ()), *values.get("BASE_ROT", ())]
        else:
            exp.append(key.qpos[model.jnt_qposadr[j]])
            act.append(joints.get(model.joint(j).name, math.nan))
    found.append(
        compare(
            "training.mjlab.home",
            "HOME_JOINTS (and a floating base's BASE_POS, BASE_ROT) vs the GPU scene's keyframe",
            exp,
            act,
            1e-9,
            "rad or m",
        )
    )
    return found


def expected_training(doc: dict) -> str | None:
    """Why robot.json says this kit has no `training/` (a GPU scene file, position servos, all
    with finite efforts), or None when it must have one. Read from robot.json alone, so a kit
    whose training/ was deleted fails, and one that never had it passes with the reason."""
    if not isinstance((doc.get("gpu_scene") or {}).get("file"), str):
        return "no GPU scene to train on"
    servos = doc.get("actuators") or []
    if not servos:
        return "no position servos: neither a reach nor a stance task can act"
    efforts = [a.get("forcerange") for a in servos]
    if any(e is None or not math.isfinite(float(e)) for e in efforts):
        return "a servo without an effort limit"
    return None


def check_training(kit: Kit) -> list[Finding]:
    """The three training files against the GPU scene and the USD (none: nothing to check)."""
    files = (layout.PLAYGROUND_ENV, layout.MJLAB_CFG, layout.ISAACLAB_CFG)
    present = [f for f in files if kit.path(f).is_file()]
    expected = expected_training(kit.doc)
    if not present:
        why = "no training/ in this kit" + (f" ({expected})" if expected else "")
        return [require("training.present", expected is not None, why)]
    if expected is not None:
        return [require("training.present", False, f"training/ in a kit without one: {expected}")]
    if len(present) != len(files):
        return [require("training.present", False, f"training/ has only {present}")]
    from simkit.check.training_usd import check_isaaclab

    velocities = {j["name"]: j.get("max_velocity") for j in kit.joints}
    return _playground(kit, velocities) + _mjlab(kit, velocities) + check_isaaclab(kit)
