"""Loop closures (spec `loops`) as the written kit carries them, read from the files only.

robot.json lists each loop (`loops`: link2's pose in link1's frame at home). The checks:

- `loops.home`: robot.json's own joints at home (check/connected.py `home_poses`) put link2
  at that pose in link1's frame, so the closure holds where the kit starts;
- `loops.mjcf`: the MJCF's weld equalities are exactly robot.json's loops, each between the
  same bodies (the root: MuJoCo's world) at the same `relpose`;
- `loops.hold`: MuJoCo, on the MJCF with the position servos, starts at home with the
  servos aimed at home and runs `HOLD_SECONDS`: each loop's link2 stays within `HOLD_M` /
  `HOLD_RAD` of its pose in link1's frame (a tampered relpose pulls the robot away);
- `loops.pairs`: each pair robot.json excludes around a loop (`collision_pairs.loop`) sits
  around one and touches at home in the MJCF;
- `usd_findings` (called by check/usd.py per physics variant): the USD's joints excluded
  from the articulation are exactly the loops, between the same bodies at the same pose.

A kit without loops (and without welds) gets no finding, so such kits are unchanged.
"""

from __future__ import annotations

import mujoco
import numpy as np

from simkit.check.always import body_geoms, pair_depth
from simkit.check.connected import home_poses
from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.check.mujoco import HOLD_SECONDS, load_control_mjcf, load_mjcf
from simkit.model.kinematics import quat_matrix, rpy_matrix, transform

#: m and rad: how far a welded link may drift from its pose after the hold (the weld's own
#: compliance is far smaller, MIMIC_* in emit/mjcf.py)
HOLD_M = 1e-3
HOLD_RAD = 0.01
#: m / rad: a written pose matches robot.json's (10-digit numbers in both files)
POSE_TOL = 1e-6
#: m: a pair excluded around a loop is closer than this at home (float32 mesh files)
TOUCH = 1e-5


def _loops(kit: Kit) -> list[dict]:
    return kit.doc.get("loops", [])


def _pose(loop: dict) -> np.ndarray:
    """T_link1_link2 as robot.json gives it (4x4)."""
    return transform(loop["origin_xyz"], rpy_matrix(loop["origin_rpy"]))


def _difference(expected: np.ndarray, actual: np.ndarray) -> tuple[float, float]:
    """(distance m, angle rad) between two 4x4 poses."""
    rot = expected[:3, :3].T @ actual[:3, :3]
    angle = float(np.arccos(np.clip((np.trace(rot) - 1) / 2, -1.0, 1.0)))
    return float(np.linalg.norm(expected[:3, 3] - actual[:3, 3])), angle


def check_loops(kit: Kit) -> list[Finding]:
    """`loops.home`, `loops.mjcf` and `loops.hold` (module docstring)."""
    loops = _loops(kit)
    if not loops and b"<weld" not in kit.path(kit.mjcf).read_bytes():
        return []  # no loop, no weld: nothing to compare (and no model to compile)
    mj = load_mjcf(kit)
    welds = [e for e in range(mj.neq) if mj.eq_type[e] == mujoco.mjtEq.mjEQ_WELD]
    if not loops and not welds:
        return []
    findings = [_home(kit, loops), _mjcf(kit, mj, welds, loops)]
    if findings[-1].ok:
        findings.append(_hold(kit, loops))
    pairs = (kit.doc.get("collision_pairs") or {}).get("loop", [])
    if pairs:
        findings.append(_pairs(kit, mj, pairs, loops))
    return findings


def _pairs(kit: Kit, mj, pairs: list, loops: list[dict]) -> Finding:
    """`loops.pairs`: each pair robot.json excludes around a loop (`collision_pairs.loop`)
    joins a welded link or its neighbour (by robot.json's joints or loops) to the other
    welded link or its neighbour, and touches at home in the MJCF (within `TOUCH`)."""
    near: dict[str, set[str]] = {}
    joined = [(j["parent"], j["child"]) for j in kit.joints + kit.doc.get("fixed_joints", [])]
    for a, b in joined + [(lp["link1"], lp["link2"]) for lp in loops]:
        near.setdefault(a, {a}).add(b)
        near.setdefault(b, {b}).add(a)
    data = mujoco.MjData(mj)
    for joint, value in zip(kit.joints, kit.doc.get("home") or [], strict=False):
        data.qpos[mj.jnt_qposadr[mj.joint(joint["name"]).id]] = value
    mujoco.mj_kinematics(mj, data)
    wrong = []
    for a, b in pairs:
        around = any(
            (a in near.get(lp["link1"], ()) and b in near.get(lp["link2"], ()))
            or (b in near.get(lp["link1"], ()) and a in near.get(lp["link2"], ()))
            for lp in loops
        )
        if not around:
            wrong.append(f"{a}-{b}: not around a loop")
        elif pair_depth(mj, data, body_geoms(mj, a), body_geoms(mj, b), TOUCH) < -TOUCH:
            wrong.append(f"{a}-{b}: apart at home")
    return require(
        "loops.pairs",
        not wrong,
        "pairs excluded around a loop touch at home" + (f"; {'; '.join(wrong)}" if wrong else ""),
    )


def _home(kit: Kit, loops: list[dict]) -> Finding:
    poses = home_poses(kit)
    errors, names = [], []
    for loop in loops:
        a, b = poses.get(loop["link1"]), poses.get(loop["link2"])
        if a is None or b is None:
            return require("loops.home", False, f"loop '{loop['name']}': a link is not in the tree")
        errors.append(_difference(_pose(loop), np.linalg.inv(a) @ b))
        names.append(loop["name"])
    return compare(
        "loops.home",
        "each loop's link2 in link1's frame at home (robot.json's joints) vs the loop's pose",
        np.zeros((len(errors), 2)),
        np.reshape(errors, (-1, 2)),
        POSE_TOL,
        "m or rad",
        names,
    )


def _body(kit: Kit, name: str) -> str:
    """The MJCF body of a loop's link: the root frame (no link) is MuJoCo's world body."""
    return name if name in _links(kit) else "world"


def _links(kit: Kit) -> set[str]:
    return {link["name"] for link in kit.doc["links"]}


def _mjcf(kit: Kit, mj, welds: list[int], loops: list[dict]) -> Finding:
    written = {mj.equality(e).name: e for e in welds}
    listed = {loop["name"]: loop for loop in loops}
    if set(written) != set(listed):
        return require(
            "loops.mjcf",
            False,
            f"MJCF welds {sorted(written)} are not robot.json's loops {sorted(listed)}",
        )
    wrong = []
    for name, loop in sorted(listed.items()):
        e = written[name]
        bodies = (mj.body(int(mj.eq_obj1id[e])).name, mj.body(int(mj.eq_obj2id[e])).name)
        if bodies != (_body(kit, loop["link1"]), _body(kit, loop["link2"])):
            wrong.append(f"{name}: bodies {bodies}")
            continue
        data = mj.eq_data[e]  # anchor (3), relpose position (3) and quaternion (4), torquescale
        pose = transform(data[3:6], quat_matrix(data[6:10]))
        distance, angle = _difference(_pose(loop), pose)
        if max(distance, angle) > POSE_TOL:
            wrong.append(f"{name}: relpose off by {distance:.3g} m, {angle:.3g} rad")
    return require(
        "loops.mjcf",
        not wrong,
        "a weld per robot.json loop, between its links at its pose"
        + (f"; {'; '.join(wrong)}" if wrong else ""),
    )


def _hold(kit: Kit, loops: list[dict]) -> Finding:
    mj = load_control_mjcf(kit)
    data = mujoco.MjData(mj)
    names = [j["name"] for j in kit.joints]
    home = kit.doc.get("home") or [0.0] * len(names)
    for name, value in zip(names, home, strict=True):
        data.qpos[mj.jnt_qposadr[mj.joint(name).id]] = value
        act = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        if act >= 0:
            data.ctrl[act] = value
    for _ in range(round(HOLD_SECONDS / mj.opt.timestep)):
        mujoco.mj_step(mj, data)
    drift = []
    for loop in loops:
        ends = [mj.body(_body(kit, loop[k])).id for k in ("link1", "link2")]
        a, b = (transform(data.xpos[i], data.xmat[i].reshape(3, 3)) for i in ends)
        drift.append(_difference(_pose(loop), np.linalg.inv(a) @ b))
    return compare(
        "loops.hold",
        f"each loop's link2 in link1's frame after {HOLD_SECONDS:g} s on the servos at home "
        f"(tolerance {HOLD_M:g} m; {HOLD_RAD:g} rad scaled to it)",
        np.zeros((len(drift), 2)),
        np.reshape(drift, (-1, 2)) * [1.0, HOLD_M / HOLD_RAD],
        HOLD_M,
        "m (rad scaled)",
        [loop["name"] for loop in loops],
    )


def usd_findings(kit: Kit, stage, root: str) -> list[Finding]:
    """`usd.loops`: the USD's joints excluded from the articulation are robot.json's loops,
    each FixedJoint between the loop's links (the root frame: `root`) at its pose."""
    from simkit.check.readers.usd import loop_joints, prim_name

    loops = _loops(kit)
    joints = loop_joints(stage)
    if not loops and not joints:
        return []
    links = _links(kit)
    wrong = []
    if set(joints) != {prim_name(lp["name"]) for lp in loops}:
        wrong.append(f"excluded joints {sorted(joints)} are not the loops")
    for loop in loops if not wrong else []:
        body0, body1, pose0, pose1 = joints[prim_name(loop["name"])]
        want = tuple(
            f"{root}/{prim_name(n)}" if n in links else root for n in (loop["link1"], loop["link2"])
        )
        if (body0, body1) != want:
            wrong.append(f"{loop['name']}: bodies {body0}, {body1}")
            continue
        distance, angle = _difference(_pose(loop), pose0 @ np.linalg.inv(pose1))
        if max(distance, angle) > 1e-5:  # USD stores float poses
            wrong.append(f"{loop['name']}: pose off by {distance:.3g} m, {angle:.3g} rad")
    return [
        require(
            "usd.loops",
            not wrong,
            "a fixed joint excluded from the articulation per robot.json loop, at its pose"
            + (f"; {'; '.join(wrong)}" if wrong else ""),
        )
    ]
