"""`training/isaaclab_cfg.py` against the composed USD stage (issue 41).

Isaac Sim cannot run here, so the config is read with `ast` (never imported: Isaac Lab is not
installed) and every value is compared with what Isaac Lab would read from the USD asset it
spawns: the drives' stiffness and damping (USD: per degree), maxForce, the PhysX joint axis'
maxJointVelocity (deg/s) and armature, the joint limits (the home pose must lie within them),
and for a floating base its start pose (the base body's Xform).
"""

from __future__ import annotations

import ast
import math

import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.check.readers.usd import (
    joints_from_parser,
    joints_from_schemas,
    parse_physics,
    prim_name,
)
from simkit.kitio import layout

#: USD stores Float (32-bit) values: relative tolerance
RELATIVE = 1e-6
#: ImplicitActuatorCfg keyword -> index into the stage's joint record below
FIELDS = ("stiffness", "damping", "effort_limit_sim", "velocity_limit_sim", "armature")


def _keywords(call: ast.Call) -> dict[str, ast.expr]:
    return {k.arg: k.value for k in call.keywords if k.arg is not None}


def _call(node: ast.AST, name: str) -> ast.Call | None:
    """The first call in `node` to a callable ending in `name` (ArticulationCfg, ...)."""
    for sub in ast.walk(node):
        if isinstance(sub, ast.Call):
            func = sub.func
            called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if called == name:
                return sub
    return None


def read_config(text: str) -> dict:
    """The ArticulationCfg's USD path, initial state and actuator groups, from the source."""
    tree = ast.parse(text)
    cfg = _call(tree, "ArticulationCfg")
    if cfg is None:
        raise ValueError("no ArticulationCfg(...) call")
    top = _keywords(cfg)
    path = _call(top["spawn"], "join")
    files = next(
        (
            ast.literal_eval(node.value)
            for node in tree.body
            if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", None) == "USD_FILES"
        ),
        (),
    )
    init = _keywords(_call(top["init_state"], "InitialStateCfg"))  # type: ignore[arg-type]
    groups = {}
    assert isinstance(top["actuators"], ast.Dict)
    for key, value in zip(top["actuators"].keys, top["actuators"].values, strict=True):
        kw = _keywords(value)  # type: ignore[arg-type]
        groups[ast.literal_eval(key)] = {k: ast.literal_eval(v) for k, v in kw.items()}  # type: ignore[arg-type]
    return {
        # usd_path=os.path.join(KIT_DIR, USD), USD the first of USD_FILES the kit holds
        "usd": files if path is not None and getattr(path.args[-1], "id", "") == "USD" else (),
        "pos": ast.literal_eval(init["pos"]),
        "rot": ast.literal_eval(init["rot"]),
        "joint_pos": ast.literal_eval(init["joint_pos"]),
        "groups": groups,
    }


def _stage_joints(stage) -> dict[str, dict]:
    """name -> kind, limit (rad or m), and the drive values in Isaac Lab's units, per joint."""
    parsed = parse_physics(stage)
    joints = joints_from_parser(parsed) if parsed is not None else joints_from_schemas(stage)
    out = {}
    for j in joints:
        if j.kind == "fixed":
            continue
        angular = j.kind == "revolute"
        unit = math.radians if angular else float
        prim = stage.GetPrimAtPath(j.path)
        axis = "angular" if angular else "linear"

        def physx(what: str, prim=prim, axis=axis) -> float | None:
            attr = prim.GetAttribute(f"physxJointAxis:{axis}:{what}")
            value = attr.Get() if attr and attr.HasAuthoredValue() else None
            return None if value is None else float(value)

        velocity = physx("maxJointVelocity")
        record = {
            "limit": tuple(unit(v) for v in j.limit) if j.limit is not None else None,
            "servo": j.drive is not None and math.isfinite(j.drive[2]),
        }
        if record["servo"]:
            per = 180.0 / math.pi if angular else 1.0  # USD gains are per degree
            record["values"] = (
                j.drive[0] * per,  # type: ignore[index]
                j.drive[1] * per,  # type: ignore[index]
                j.drive[2],  # type: ignore[index]
                None if velocity is None else unit(velocity),
                physx("armature") or 0.0,
            )
        out[j.path.rsplit("/", 1)[-1]] = record
    return out


def _close(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return abs(float(a) - float(b)) <= RELATIVE * max(1.0, abs(float(a)))


def _group_findings(config: dict, joints: dict[str, dict]) -> list[Finding]:
    wrong, covered = [], []
    for name, group in config["groups"].items():
        for joint in group.get("joint_names_expr", []):
            covered.append(joint)
            record = joints.get(joint)
            if record is None or not record["servo"]:
                wrong.append(f"{name}/{joint}: no servo drive in the USD")
                continue
            for field, value in zip(FIELDS, record["values"], strict=True):
                if not _close(value, group.get(field)):
                    wrong.append(f"{joint}.{field}: {group.get(field)} (USD {value})")
    servos = sorted(n for n, r in joints.items() if r["servo"])
    return [
        require(
            "training.isaaclab.actuators",
            not wrong and sorted(covered) == servos,
            "every USD servo drive in exactly one actuator group, with its stiffness, damping, "
            "effort and velocity limits and armature"
            + (f" (differ: {wrong[:4]})" if wrong else "")
            + ("" if sorted(covered) == servos else f" (groups {sorted(covered)}, USD {servos})"),
        )
    ]


def _state_findings(kit: Kit, stage, config: dict, joints: dict[str, dict]) -> list[Finding]:
    from pxr import UsdGeom

    pose = kit.doc.get("poses", {})
    names = [j["name"] for j in kit.joints]
    home = dict(
        zip(names, pose.get("home") or next(iter(pose.values()), [0.0] * len(names)), strict=True)
    )
    written = config["joint_pos"]
    outside = [
        n
        for n, q in written.items()
        if joints.get(n, {}).get("limit") is not None
        and not joints[n]["limit"][0] - 1e-6 <= q <= joints[n]["limit"][1] + 1e-6
    ]
    found = [
        require(
            "training.isaaclab.limits",
            not outside and set(written) == set(joints),
            f"joint_pos names every USD joint and lies within its limits (outside: {outside})",
        ),
        compare(
            "training.isaaclab.home",
            "joint_pos vs robot.json's home pose",
            [home.get(n, math.nan) for n in sorted(written)],
            [written[n] for n in sorted(written)],
            1e-9,
            "rad or m",
        ),
    ]
    floating = kit.doc.get("floating_base")
    if floating:
        base = prim_name(floating["child"])
        prim = stage.GetPrimAtPath(f"{stage.GetDefaultPrim().GetPath()}/{base}")
        world = np.array(UsdGeom.XformCache().GetLocalToWorldTransform(prim)).T
        found.append(
            compare(
                "training.isaaclab.base",
                "init_state pos vs the base body's Xform in the USD",
                world[:3, 3],
                config["pos"],
                1e-6,
                "m",
            )
        )
    return found


def check_isaaclab(kit: Kit) -> list[Finding]:
    """training/isaaclab_cfg.py vs the composed USD stage (default physics variant)."""
    from pxr import Usd

    try:
        config = read_config(kit.path(layout.ISAACLAB_CFG).read_text(encoding="utf-8"))
    except (SyntaxError, ValueError, KeyError, AssertionError, TypeError) as exc:
        return [require("training.isaaclab.read", False, f"isaaclab_cfg.py: {exc}")]
    usd = next((f for f in config["usd"] if kit.path(f).is_file()), None)
    if usd is None:
        return [require("training.isaaclab.usd", False, f"no USD_FILES {config['usd']} in the kit")]
    stage = Usd.Stage.Open(str(kit.path(usd)), Usd.Stage.LoadAll)
    joints = _stage_joints(stage)
    return [
        require("training.isaaclab.usd", True, f"usd_path {usd} opens"),
        *_group_findings(config, joints),
        *_state_findings(kit, stage, config, joints),
    ]
