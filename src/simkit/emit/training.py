"""`training/` (issue 41): the kit one import away in MuJoCo Playground, mjlab and Isaac Lab.

Three Python files from templates/training/, each opening with the kit's own values as plain
literals (servo gains, effort and velocity limits, armature, the home keyframe, the named
sensors, the foot colliders), read here from the one model so no value is copied by hand.
`check/training.py` reads those literals back with `ast` and compares them with the written
GPU scene (MuJoCo) and the composed USD stage (pxr) on every build.

Why: gains and limits copied wrong between formats, missing Playground variants and missing
Isaac Lab configs are what users of those frameworks report most.
"""

from __future__ import annotations

import json
import math

from simkit.emit.mjcf_scene import key_qpos
from simkit.emit.templating import environment
from simkit.emit.training_sensors import ROLES, base_sensors
from simkit.emit.usd.mimic import driven_follower
from simkit.kitio import layout
from simkit.kitio.fmt import num
from simkit.model.robot import Robot

#: The pose the environments start from: the spec's `home`, else its first named pose.
HOME = "home"


def py(value) -> str:
    """A Python literal of `value` (floats through the one number formatter)."""
    if value is None or isinstance(value, bool):
        return repr(value)
    if isinstance(value, (int, float)):
        return num(value)
    if isinstance(value, str):
        return json.dumps(value)  # double quotes, as ruff formats Python
    if isinstance(value, tuple | list):
        inner = ", ".join(py(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{py(k)}: {py(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"no Python literal for {type(value).__name__}")


def home_pose(robot: Robot) -> tuple[str, tuple[float, ...]]:
    """(name, joint values in movable-joint order): `home`, else the first pose, else zeros."""
    poses = dict(robot.poses)
    if HOME in poses:
        return HOME, tuple(poses[HOME])
    if robot.poses:
        return robot.poses[0][0], tuple(robot.poses[0][1])
    return "zero", (0.0,) * len(robot.movable_joints)


def actuators(robot: Robot) -> dict[str, dict]:
    """Per servo (MJCF actuator order, named by its joint): kp (N m/rad or N/m), kv (N m s/rad
    or N s/m), effort (N m or N), range (rad or m; None for a continuous joint), velocity
    (rad/s or m/s; None where the spec gives none) and armature (kg m^2 or kg)."""
    out: dict[str, dict] = {}
    for act in robot.actuators:
        joint = robot.joint(act.joint)
        limited = joint.lower is not None and joint.type != "continuous"
        out[act.joint] = {
            "kp": act.kp,
            "kv": act.kv,
            "effort": act.forcerange,
            "range": (joint.lower, joint.upper) if limited else None,
            "velocity": joint.max_velocity or None,
            "armature": joint.armature,
        }
    return out


def isaac_actuators(robot: Robot, acts: dict[str, dict]) -> dict[str, dict]:
    """The servos the USD drives (`acts`, from `actuators`), plus each prismatic mimic
    follower the USD drives with its leader's servo (emit/usd/mimic.py `driven_follower`:
    PhysX does not couple a linear mimic), with the follower's own range, velocity and
    armature."""
    out = dict(acts)
    for joint in robot.movable_joints:
        if joint.name in out or not driven_follower(robot, joint):
            continue
        lead = out[joint.mimic[0]]
        out[joint.name] = {
            **lead,
            "range": (joint.lower, joint.upper) if joint.lower is not None else None,
            "velocity": joint.max_velocity or None,
            "armature": joint.armature,
        }
    return out


def feet(robot: Robot) -> tuple[str, ...]:
    """A floating robot's floor-pair colliders within 1 cm of the floor at home (the GPU
    scene's plan; derive/gpu_scene.py's own rule)."""
    plan = robot.products.gpu_scene or {}
    if not robot.floating_base or not plan.get("floor_pairs"):
        return ()
    from simkit.derive.gpu_scene import standing_colliders

    touching = standing_colliders(robot, plan.get("colliders", []))
    return tuple(sorted(set(plan["floor_pairs"]) & touching))


def values(robot: Robot) -> dict:
    """The literals the three files share, each already a Python literal string."""
    pose, q = home_pose(robot)
    by_joint = dict(zip([j.name for j in robot.movable_joints], q, strict=True))
    acts = actuators(robot)
    timestep = robot.mjcf.timestep if robot.mjcf is not None else 0.002
    sensors = base_sensors(robot)
    floating = robot.floating_joint
    return {
        "kit": py(robot.name),
        "scene": py(layout.mjcf_mjx(robot.name)),
        # the Isaac asset's interface layer, text or binary (`--usd-format`)
        "usd": py((layout.usd_asset(robot.name), layout.usd_asset(robot.name, True))),
        "floating": py(robot.floating_base),
        "timestep": py(timestep),
        "actuators": "{\n"
        + "".join(f"    {py(name)}: {py(v)},\n" for name, v in acts.items())
        + "}",
        "home_name": py(pose),
        "home_qpos": py(tuple(key_qpos(robot, q))),
        "home_joints": py({name: by_joint[name] for name in by_joint}),
        "home_ctrl": py(tuple(by_joint[name] for name in acts)),
        "base_pos": py(tuple(floating.xyz) if floating is not None else (0.0, 0.0, 0.0)),
        "base_rot": py(_base_quat(robot)),
        "sensors": py({role: sensors[role] for role in ROLES if role in sensors}),
        "named_sensors": py(
            tuple(s.name for s in robot.mjcf.sensors) if robot.mjcf is not None else ()
        ),
        "feet": py(feet(robot)),
        "groups": _groups(isaac_actuators(robot, acts)),
    }


def _base_quat(robot: Robot) -> tuple[float, ...]:
    qpos = key_qpos(robot, home_pose(robot)[1])
    return tuple(qpos[3:7]) if robot.floating_base else (1.0, 0.0, 0.0, 0.0)


def _groups(acts: dict[str, dict]) -> list[dict]:
    """Isaac Lab actuator groups: joints with the same stiffness, damping, effort, velocity and
    armature share one `ImplicitActuatorCfg`, named by its first joint."""
    groups: dict[tuple, list[str]] = {}
    for name, v in acts.items():
        key = (v["kp"], v["kv"], v["effort"], v["velocity"], v["armature"])
        groups.setdefault(key, []).append(name)
    return [
        {
            "name": py(names[0]),
            "joints": py(tuple(names)),
            "stiffness": py(key[0]),
            "damping": py(key[1]),
            "effort": py(key[2]),
            "velocity": py(key[3]),
            "armature": py(key[4]),
        }
        for key, names in groups.items()
    ]


def reason_none(robot: Robot) -> str | None:
    """Why a kit gets no `training/` (one line), or None when it gets one."""
    plan = robot.products.gpu_scene
    if plan is None or "none" in plan:  # none: the GPU scene's own line says why
        return "no GPU scene to train on"
    if not robot.actuators:
        return "no position servos: neither a reach nor a stance task can act"
    if any(not math.isfinite(a.forcerange) for a in robot.actuators):
        return "a servo without an effort limit"
    return None


def readme(robot: Robot) -> dict:
    """Values for the kit README's training section (None: no training/)."""
    if reason_none(robot) is not None:
        return {"training": None}
    task = (
        "The Playground task, a starting point: stand and hold a commanded base velocity of zero."
        if robot.floating_base
        else "The Playground task, a starting point: reach a joint-space target sampled within "
        "the joint limits."
    )
    return {
        "training": {"home": home_pose(robot)[0], "task": task, "usd": layout.usd_asset(robot.name)}
    }


def emit(robot: Robot) -> dict[str, bytes]:
    """`training/playground_env.py`, `training/mjlab_cfg.py`, `training/isaaclab_cfg.py`."""
    if reason_none(robot) is not None:
        return {}
    env, ctx = environment(), values(robot)
    ctx["spec"], ctx["title"] = robot.spec_file, robot.title
    files = {
        layout.PLAYGROUND_ENV: "training/playground_env.py.j2",
        layout.MJLAB_CFG: "training/mjlab_cfg.py.j2",
        layout.ISAACLAB_CFG: "training/isaaclab_cfg.py.j2",
    }
    return {path: env.get_template(t).render(ctx).encode("utf-8") for path, t in files.items()}
