"""Checks of an arm kit's motion data, read from the written files: ik_cases.json (the kit
page's snippet logic and more), the 1 kg benchmark trajectory (limits, TCP points, MuJoCo
inverse dynamics against the forcerange) and the derived accelerations (MuJoCo mass matrix).

Source: 000_5f76ade803e16979.txt, "Accelerations and motion profiles", "Benchmark cycle",
"IK reference cases". Kits without these products (no `motion` in robot.json) get no findings.
"""

from __future__ import annotations

import csv
import json

import mujoco
import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.model.kinematics import axis_angle, rpy_matrix, transform
from simkit.simulate.benchmark import inverse_dynamics_model, kit_model_check, mesh_assets
from simkit.simulate.loaders import load_urdf_text

N_CASES = 12  # kit page: "It holds twelve cases"
TCP_TOL = 1e-4  # m: the trajectory passes through the six TCP points within 0.1 mm
ACC_REL_TOL = 1e-3  # derived accelerations vs MuJoCo's mass matrix and bias forces
LIMIT_SLACK = 1e-9  # relative: velocity and acceleration bounds
MAX_STEP = 0.1  # rad between two steps of a resolved move (ik_cases.MAX_STEP)


def _at_most(check: str, detail: str, value: float, limit: float, slack: float = 0.0) -> Finding:
    """Finding for value <= limit * (1 + slack), reporting the value itself."""
    ok = bool(np.isfinite(value) and value <= limit * (1 + slack))
    return Finding(check, ok, detail, f"<= {limit:g}", f"{value:.6g}", f"{slack:g} relative", "")


def _chain_fk(chain: dict, q) -> np.ndarray:
    """FK from ik_cases.json alone, as the kit page's snippet, with the file's tool frame."""
    T = np.eye(4)
    for joint, value in zip(chain["joints"], q, strict=True):
        T = T @ transform(joint["origin_xyz"], axis_angle(joint["axis"], value))
    return T @ np.asarray(chain["tool"]["T_parent_tool"])


def _error(T: np.ndarray, target: dict) -> float:
    return float(
        max(
            np.abs(T[:3, 3] - target["xyz"]).max(),
            np.abs(T[:3, :3] - np.asarray(target["rotation"])).max(),
        )
    )


def check_ik_cases(kit: Kit) -> list[Finding]:
    """ik_cases.json: twelve cases; every solution within the limits and reaching the target
    within the file's tolerance; chain equal to robot.json's; moves straight and continuous."""
    ref = kit.doc.get("ik_reference")
    if ref is None:
        return []
    path = kit.path(ref["file"])
    if not path.is_file():
        return [require("ik_cases.file", False, f"{ref['file']} is missing")]
    doc = json.loads(path.read_text(encoding="utf-8"))
    tol = doc["tolerance"]["position_m"]
    joints = {j["name"]: j for j in kit.joints}
    chain = doc["chain"]
    out = [
        require(
            "ik_cases.count",
            len(doc["cases"]) == N_CASES,
            f"{len(doc['cases'])} cases (kit page: twelve)",
        )
    ]
    out.append(
        compare(
            "ik_cases.chain",
            "chain origins and axes vs robot.json joints",
            [
                [*joints[j["name"]]["origin_xyz"], *joints[j["name"]]["axis"]]
                for j in chain["joints"]
            ],
            [[*j["origin_xyz"], *j["axis"]] for j in chain["joints"]],
            0.0,
            "m",
        )
    )
    lower = np.array([joints[j["name"]]["lower"] for j in chain["joints"]])
    upper = np.array([joints[j["name"]]["upper"] for j in chain["joints"]])
    worst, outside, kit_fk, line, steps, distinct = 0.0, 0, 0.0, 0.0, 0.0, True
    for case in doc["cases"]:
        sols = [case["expected"]] + case["all_solutions"]
        qs = np.array([s["q"] for s in sols])
        for q in qs:
            worst = max(worst, _error(_chain_fk(chain, q), case["target"]))
            outside += int(np.any(q < lower - 1e-12) or np.any(q > upper + 1e-12))
        diffs = np.abs(qs[:, None, :] - qs[None, :, :]).max(axis=2) + np.eye(len(qs))
        distinct &= bool(diffs.min() > 1e-6)
        kit_fk = max(kit_fk, _error(kit.fk(case["expected"]["q"]), case["target"]))
        move = np.asarray(case["move"]["q"])
        steps = max(
            steps,
            float(np.abs(np.diff(move, axis=0)).max()),
            float(np.abs(move[0] - case["seed"]["q"]).max()),
            float(np.abs(move[-1] - case["expected"]["q"]).max()),
        )
        start = np.asarray(case["seed"]["tool0"]["xyz"])
        direction = np.asarray(case["target"]["xyz"]) - start
        direction /= np.linalg.norm(direction)
        for q in move:
            r = _chain_fk(chain, q)[:3, 3] - start
            line = max(line, float(np.linalg.norm(r - direction * (direction @ r))))
    out += [
        compare(
            "ik_cases.reach",
            "every expected and all_solutions entry reaches its target (kit page snippet)",
            0.0,
            worst,
            tol,
            "m",
        ),
        compare("ik_cases.limits", "solutions outside the joint limits", 0, outside, 0, ""),
        require("ik_cases.distinct", distinct, "no solution listed twice in a case"),
        compare(
            "ik_cases.robot_json_fk",
            "expected solutions through robot.json FK",
            0.0,
            kit_fk,
            tol,
            "m",
        ),
        compare(
            "ik_cases.move_line", "resolved moves stay on the straight line", 0.0, line, tol, "m"
        ),
        compare(
            "ik_cases.move_continuous",
            "largest joint step along a resolved move, from the seed to the expected solution",
            0.0,
            steps,
            MAX_STEP,
            "rad",
        ),
    ]
    return out


def _payload(kit: Kit, payload: dict) -> dict:
    """The payload with its CoM in the tool frame's parent link (for MuJoCo)."""
    frame = kit.doc["frames"][payload["frame"]]
    T = transform(frame["xyz"], rpy_matrix(frame["rpy"]))
    com = (T @ np.array([*payload["com_xyz"], 1.0]))[:3]
    return {**payload, "link": frame["parent"], "com_link": list(com)}


def _urdf_with_payload(kit: Kit, payload: dict) -> mujoco.MjModel:
    """The kit's URDF in MuJoCo with the payload as a fixed child link of its parent link,
    robot.json's armature on every joint (URDF has no armature element), contacts off."""
    com = " ".join(repr(float(v)) for v in payload["com_link"])
    ixx, iyy, izz = (repr(float(v)) for v in payload["inertia_diag"])
    extra = (
        f'<link name="simkit_payload"><inertial><origin xyz="{com}" rpy="0 0 0"/>'
        f'<mass value="{float(payload["mass"])!r}"/><inertia ixx="{ixx}" iyy="{iyy}" '
        f'izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        f'<joint name="simkit_payload_joint" type="fixed"><parent link="{payload["link"]}"/>'
        '<child link="simkit_payload"/></joint></robot>'
    )
    urdf = kit.path(kit.urdf)
    text = urdf.read_text(encoding="utf-8")
    head, sep, _ = text.rpartition("</robot>")
    model = load_urdf_text(head + extra if sep else text, urdf)
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    for joint in kit.joints:
        model.dof_armature[model.jnt_dofadr[model.joint(joint["name"]).id]] = joint["armature"]
    return model


def _urdf_inverse_dynamics(
    kit: Kit, payload: dict, names: list[str], motion: tuple, recorded: list[float]
) -> Finding:
    """The independent path for `benchmarks.kit_model_check`: MuJoCo inverse dynamics on the
    kit's URDF (another file, another emitter) along the 1 kg cycle, relative to the largest
    recorded torque."""
    model = _urdf_with_payload(kit, payload)
    data = mujoco.MjData(model)
    qadr = [int(model.jnt_qposadr[model.joint(n).id]) for n in names]
    dadr = [int(model.jnt_dofadr[model.joint(n).id]) for n in names]
    peak = np.zeros(len(names))
    for q, qd, qdd in zip(*motion, strict=True):
        data.qpos[qadr], data.qvel[dadr], data.qacc[dadr] = q, qd, qdd
        mujoco.mj_inverse(model, data)
        peak = np.maximum(peak, np.abs(data.qfrc_inverse[dadr]))
    scale = max(max(recorded), 1e-9)
    return compare(
        "benchmark.urdf_inverse_dynamics",
        "largest torque per joint along the 1 kg cycle: MuJoCo on the URDF vs robot.json "
        "(relative to the largest)",
        np.asarray(recorded) / scale,
        peak / scale,
        1e-6,
        "",
        names,
    )


def _trajectory(kit: Kit, files: dict) -> tuple[list[str], np.ndarray]:
    with kit.path(files["csv"]).open(encoding="utf-8", newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], np.array(rows[1:], dtype=float)


def check_benchmark(kit: Kit) -> list[Finding]:
    """The 1 kg cycle: 1 ms samples, speeds and accelerations within bounds, the six TCP
    points hit, JSON equal to CSV, and MuJoCo inverse dynamics within every forcerange."""
    bench = kit.doc.get("benchmarks")
    if bench is None:
        return []
    files = bench["trajectory_files"]["cycle_1kg"]
    if not kit.path(files["csv"]).is_file() or not kit.path(files["json"]).is_file():
        return [require("benchmark.files", False, f"{files['csv']} or {files['json']} missing")]
    header, data = _trajectory(kit, files)
    names = bench["acceleration"]["joints"]
    n = len(names)
    t, q, qd, qdd, tcp = (
        data[:, 0],
        data[:, 1 : 1 + n],
        data[:, 1 + n : 1 + 2 * n],
        data[:, 1 + 2 * n : 1 + 3 * n],
        data[:, 1 + 3 * n : 4 + 3 * n],
    )
    joints = {j["name"]: j for j in kit.joints}
    vmax = np.array([joints[name]["max_velocity"] for name in names])
    amax = np.array(bench["acceleration"]["cycle_1kg"]["rad_s2"])
    dt = files["dt"]
    out = [
        compare("benchmark.dt", "sample spacing", np.full(len(t) - 1, dt), np.diff(t), 1e-9, "s"),
        compare(
            "benchmark.cycle_time",
            "duration vs benchmarks.cycle_time",
            bench["cycle_time"]["cycle_1kg"],
            t[-1],
            dt / 2,
            "s",
        ),
        _at_most(
            "benchmark.max_velocity",
            "largest |qd| / max_velocity",
            float((np.abs(qd) / vmax).max()),
            1.0,
            LIMIT_SLACK,
        ),
        _at_most(
            "benchmark.acceleration",
            "largest |qdd| / benchmark acceleration",
            float((np.abs(qdd) / amax).max()),
            1.0,
            LIMIT_SLACK,
        ),
    ]
    # The columns must describe one motion, or the bounds above prove nothing: over each
    # 1 ms step, q moves by the trapezoid-rule integral of qd (exact for piecewise-linear qd
    # up to a kink inside the step: at most amax dt^2 / 4), and qd changes by at most
    # amax dt (the true acceleration, not only the qdd column, stays within its bound).
    step_q = np.abs(np.diff(q, axis=0) - (qd[:-1] + qd[1:]) / 2 * dt).max(axis=0)
    step_qd = np.abs(np.diff(qd, axis=0)).max(axis=0)
    out += [
        _at_most(
            "benchmark.q_integrates_qd",
            "largest |dq - mean qd dt| / (benchmark acceleration dt^2 / 4) over a step",
            float((step_q / (amax * dt**2 / 4)).max()),
            1.0,
            1e-3,
        ),
        _at_most(
            "benchmark.qd_change",
            "largest |dqd| / (benchmark acceleration dt) over a step",
            float((step_qd / (amax * dt)).max()),
            1.0,
            1e-6,
        ),
    ]
    ends = np.cumsum([0.0, *bench["segment_times"]["cycle_1kg"]])
    rows = np.rint(ends / dt).astype(int)
    points = bench["path"]["tcp_points_base_link_m"]
    expected = [points[name] for name in bench["path"]["sequence"]]
    if rows.max() < len(q):
        out.append(
            compare(
                "benchmark.tcp_points",
                "TCP at the start and the six segment ends",
                expected,
                tcp[rows],
                TCP_TOL,
                "m",
            )
        )
    else:  # a finding, not an IndexError, for a trajectory shorter than its segments
        out.append(
            require(
                "benchmark.tcp_points",
                False,
                f"the trajectory has {len(q)} samples; its segments end at sample {rows.max()}",
            )
        )
    offset = np.array([*bench["tcp"]["xyz"], 1.0])
    # every 10th sample and every segment end, so the points above are reached by q itself
    picked = sorted(set(range(0, len(q), 10)) | {int(r) for r in rows if 0 <= r < len(q)})
    fk_tcp = np.array([(kit.fk(q[row]) @ offset)[:3] for row in picked])
    out.append(
        compare(
            "benchmark.tcp_fk",
            "TCP column vs robot.json FK (every 10th sample and the segment ends)",
            fk_tcp,
            tcp[picked],
            1e-8,
            "m",
        )
    )
    doc = json.loads(kit.path(files["json"]).read_text(encoding="utf-8"))
    out.append(
        compare(
            "benchmark.json_vs_csv",
            "JSON samples equal the CSV",
            np.hstack([q, qd, qdd, tcp]),
            np.hstack([doc["q"], doc["qd"], doc["qdd"], doc["tcp"]]),
            0.0,
            "",
        )
    )
    text = kit.path(kit.mjcf).read_text(encoding="utf-8")
    payload = _payload(kit, bench["payload"]["cycle_1kg"])
    assets = mesh_assets(kit.root)
    result = kit_model_check(text, names, payload["link"], payload, q, qd, qdd, assets)
    recorded = bench["kit_model_check"]
    out.append(
        compare(
            "benchmark.kit_model_check",
            "MuJoCo inverse dynamics on the MJCF vs robot.json (fraction of forcerange)",
            recorded["fraction"],
            result["fraction"],
            1e-6,
            "",
        )
    )
    out.append(_urdf_inverse_dynamics(kit, payload, names, (q, qd, qdd), recorded["max_torque"]))
    out.append(
        _at_most(
            "benchmark.forcerange",
            "largest inverse-dynamics torque / forcerange along the 1 kg cycle",
            max(recorded["fraction"]),
            1.0,
        )
    )
    if header[1 : 1 + n] != [f"q_{name}" for name in names]:
        out.append(require("benchmark.header", False, f"CSV header {header[: 1 + n]}"))
    return out


def check_accelerations(kit: Kit) -> list[Finding]:
    """joints[].derived_max_acceleration and motion.derived_max_acceleration against MuJoCo:
    (effort_peak - |qfrc_bias|) / M_ii on the kit's MJCF with the payload attached."""
    motion = kit.doc.get("motion")
    if motion is None:
        return []
    block = motion["derived_max_acceleration"]
    names = block["joints"]
    joints = {j["name"]: j for j in kit.joints}
    text = kit.path(kit.mjcf).read_text(encoding="utf-8")
    out = []
    for key in ("stretched_rated_payload", "work_1kg"):
        case = block[key]
        payload = _payload(kit, case["payload"])
        model = inverse_dynamics_model(text, payload["link"], payload)
        data = mujoco.MjData(model)
        qadr = [int(model.jnt_qposadr[model.joint(n).id]) for n in names]
        dadr = [int(model.jnt_dofadr[model.joint(n).id]) for n in names]
        data.qpos[qadr] = case["q"]
        mujoco.mj_inverse(model, data)  # at rest, qacc = 0: the gravity torques
        bias = data.qfrc_inverse[dadr].copy()
        diag = np.empty(len(names))
        for i, dof in enumerate(dadr):  # M_ii (armature included) from unit accelerations
            data.qacc[:] = 0.0
            data.qacc[dof] = 1.0
            mujoco.mj_inverse(model, data)
            diag[i] = data.qfrc_inverse[dof] - bias[i]
        effort = np.array([joints[n]["effort_peak"] for n in names])
        acc = (effort - np.abs(bias)) / diag
        recorded = np.asarray(case["rad_s2"])
        out.append(
            compare(
                f"acceleration.{key}",
                "derived_max_acceleration vs MuJoCo mass matrix (relative)",
                np.ones(len(names)),
                recorded / acc,
                ACC_REL_TOL,
                "",
                names,
            )
        )
    per_joint = [joints[n]["derived_max_acceleration"] for n in names]
    out.append(
        compare(
            "acceleration.joints",
            "joints[] vs motion block",
            per_joint,
            block["stretched_rated_payload"]["rad_s2"],
            0.0,
            "rad/s^2",
            names,
        )
    )
    return out


def check_motion(kit: Kit) -> list[Finding]:
    """All motion-data checks (registered in CHECKS)."""
    return check_ik_cases(kit) + check_benchmark(kit) + check_accelerations(kit)
