"""Checks that load the written URDF and MJCF in MuJoCo and compare them with each other,
with robot.json, and with the published numbers."""

from __future__ import annotations

import mujoco
import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.simulate.loaders import load_urdf_file

N_RANDOM = 25
HOLD_SECONDS = 2.0
HOLD_TOLERANCE_DEG = 0.5  # kit page: "a held pose sits within a few tenths of a degree"
PARAM_TOL = 1e-6  # MJCF and robot.json both carry 10 significant digits (fmt.num, jsonout)
_JOINT = mujoco.mjtObj.mjOBJ_JOINT


def load_mjcf(kit: Kit) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(kit.path(kit.mjcf)))


def load_control_mjcf(kit: Kit) -> mujoco.MjModel:
    """The MJCF with the position servos: the scene file where the main file has none
    (robot.json `files.mjcf_scene`), else the main file."""
    return mujoco.MjModel.from_xml_path(str(kit.path(kit.doc["files"].get("mjcf_scene", kit.mjcf))))


def load_urdf_in_mujoco(kit: Kit) -> mujoco.MjModel:
    """The kit's URDF compiled in MuJoCo (`simulate.loaders.load_urdf_file`)."""
    return load_urdf_file(kit.path(kit.urdf))


def _qpos_indices(model: mujoco.MjModel, names: list[str]) -> list[int]:
    return [int(model.jnt_qposadr[model.joint(n).id]) for n in names]


def _dof_indices(model: mujoco.MjModel, names: list[str]) -> list[int]:
    return [int(model.jnt_dofadr[model.joint(n).id]) for n in names]


def random_configs(kit: Kit, count: int, seed: int = 0) -> np.ndarray:
    """Seeded random joint positions within limits (continuous joints: +-pi); a mimic joint
    follows its leader (robot.json `mimic`), as URDF readers and the MJCF equality do."""
    rng = np.random.default_rng(seed)
    lower = np.array([j["lower"] if j["lower"] is not None else -np.pi for j in kit.joints])
    upper = np.array([j["upper"] if j["upper"] is not None else np.pi for j in kit.joints])
    q = rng.uniform(lower, upper, size=(count, len(lower)))
    index = {j["name"]: i for i, j in enumerate(kit.joints)}
    for i, joint in enumerate(kit.joints):
        mimic = joint.get("mimic")
        if mimic is not None and mimic["joint"] in index:
            q[:, i] = mimic["multiplier"] * q[:, index[mimic["joint"]]] + mimic["offset"]
    return q


def check_models(kit: Kit) -> list[Finding]:
    """Compile both files; compare masses, tool FK and gravity torques between them."""
    findings: list[Finding] = []
    try:
        mj = load_mjcf(kit)
        findings.append(
            require("mjcf.compile", True, f"{kit.mjcf} compiles in MuJoCo {mujoco.__version__}")
        )
    except Exception as exc:  # MuJoCo raises ValueError with the compiler's message
        return [require("mjcf.compile", False, f"{kit.mjcf}: {exc}")]
    try:
        ur = load_urdf_in_mujoco(kit)
        findings.append(require("urdf.compile", True, f"{kit.urdf} compiles in MuJoCo"))
    except Exception as exc:
        return [*findings, require("urdf.compile", False, f"{kit.urdf}: {exc}")]

    links = [link["name"] for link in kit.doc["links"]]
    mass_json = [link["mass"] for link in kit.doc["links"]]
    mass_mj = [float(mj.body_mass[mj.body(n).id]) for n in links]
    mass_ur = [float(ur.body_mass[ur.body(n).id]) for n in links]
    findings.append(
        compare(
            "mass.mjcf", "per-link mass, MJCF vs robot.json", mass_json, mass_mj, 1e-6, "kg", links
        )
    )
    findings.append(
        compare(
            "mass.urdf", "per-link mass, URDF vs robot.json", mass_json, mass_ur, 1e-6, "kg", links
        )
    )
    inertia_mj = [mj.body_inertia[mj.body(n).id] for n in links]
    inertia_ur = [ur.body_inertia[ur.body(n).id] for n in links]
    findings.append(
        compare(
            "inertia.urdf_vs_mjcf",
            "principal inertia per link",
            inertia_mj,
            inertia_ur,
            1e-7,
            "kg m^2",
            links,
        )
    )
    findings.extend(_inertials(kit, links, mj, ur))

    names = [j["name"] for j in kit.joints]
    configs = random_configs(kit, N_RANDOM)
    tool = kit.doc.get("tool_frame", None)
    dmj, dur = mujoco.MjData(mj), mujoco.MjData(ur)
    qa, qb = _qpos_indices(mj, names), _qpos_indices(ur, names)
    va, vb = _dof_indices(mj, names), _dof_indices(ur, names)
    for j in range(mj.njnt):  # the URDF's base is the world frame: the free joint there too
        if mj.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE:
            dmj.qpos[mj.jnt_qposadr[j] + 3 : mj.jnt_qposadr[j] + 7] = (1.0, 0.0, 0.0, 0.0)
    pos_mj, pos_ur, pos_json, tau_mj, tau_ur = [], [], [], [], []
    rot_mj, rot_ur, rot_json = [], [], []
    for q in configs:
        dmj.qpos[qa], dur.qpos[qb] = q, q
        mujoco.mj_forward(mj, dmj)
        mujoco.mj_forward(ur, dur)
        tau_mj.append(dmj.qfrc_bias[va].copy())
        tau_ur.append(dur.qfrc_bias[vb].copy())
        if tool:
            base = kit.base_frame
            T_w_base_mj = body_pose(mj, dmj, base)
            T_w_base_ur = body_pose(ur, dur, base)
            T_mj = np.linalg.inv(T_w_base_mj) @ site_or_body_pose(mj, dmj, tool)
            T_ur = np.linalg.inv(T_w_base_ur) @ body_pose(ur, dur, tool)
            T_json = kit.fk(q)
            pos_mj.append(T_mj[:3, 3])
            pos_ur.append(T_ur[:3, 3])
            pos_json.append(T_json[:3, 3])
            rot_mj.append(T_mj[:3, :3])
            rot_ur.append(T_ur[:3, :3])
            rot_json.append(T_json[:3, :3])
    if tool:
        findings.append(
            compare(
                "fk.mjcf_vs_robot_json",
                f"{tool} at {N_RANDOM} random configurations",
                pos_json,
                pos_mj,
                1e-6,
                "m",
            )
        )
        findings.append(
            compare(
                "fk.urdf_vs_mjcf",
                f"{tool} at {N_RANDOM} random configurations",
                pos_mj,
                pos_ur,
                1e-6,
                "m",
            )
        )
        for check, expected, actual in (
            ("fk.mjcf_vs_robot_json.rotation", rot_json, rot_mj),
            ("fk.urdf_vs_mjcf.rotation", rot_mj, rot_ur),
        ):
            findings.append(
                compare(
                    check,
                    f"{tool} rotation at {N_RANDOM} random configurations (matrix entries)",
                    expected,
                    actual,
                    1e-6,
                    "",
                )
            )
    scale = max(1.0, float(np.max(np.abs(tau_mj), initial=0.0)))  # no joints: empty
    findings.append(
        compare(
            "gravity.urdf_vs_mjcf",
            f"gravity torques at {N_RANDOM} random configurations",
            np.array(tau_mj) / scale,
            np.array(tau_ur) / scale,
            1e-6,
            "x max torque",
        )
    )
    return findings


def _inertial_frame(model: mujoco.MjModel, name: str) -> tuple[np.ndarray, np.ndarray]:
    """CoM (m) and inertia tensor about it (kg m^2), both in the body (link) frame."""
    body = model.body(name)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, body.iquat)
    rot = rot.reshape(3, 3)
    return np.array(body.ipos), rot @ np.diag(body.inertia) @ rot.T


def _inertials(kit: Kit, links: list[str], mj: mujoco.MjModel, ur: mujoco.MjModel):
    """Each link's CoM and full inertia tensor (orientation included) in the MJCF and in the
    URDF vs robot.json. Principal moments and gravity torques alone miss a turned tensor, and
    the CoM of links that no horizontal joint moves (base_link, link_1)."""
    com_json, tensor_json = [], []
    for link in kit.doc["links"]:
        i = link["inertia"]
        com_json.append(link["com"])
        tensor_json.append(
            [
                [i["ixx"], i["ixy"], i["ixz"]],
                [i["ixy"], i["iyy"], i["iyz"]],
                [i["ixz"], i["iyz"], i["izz"]],
            ]
        )
    out = []
    for label, model in (("mjcf", mj), ("urdf", ur)):
        frames = [_inertial_frame(model, n) for n in links]
        out.append(
            compare(
                f"com.{label}",
                f"CoM per link in the link frame, {label.upper()} vs robot.json",
                com_json,
                [com for com, _ in frames],
                1e-6,
                "m",
                links,
            )
        )
        out.append(
            compare(
                f"inertia.{label}",
                f"inertia tensor per link in the link frame, {label.upper()} vs robot.json",
                tensor_json,
                [tensor for _, tensor in frames],
                1e-7,
                "kg m^2",
                links,
            )
        )
    return out


def body_pose(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> np.ndarray:
    out = np.eye(4)
    if name in ("world",) or mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) < 0:
        return out
    body = data.body(name)
    out[:3, :3] = body.xmat.reshape(3, 3)
    out[:3, 3] = body.xpos
    return out


def site_or_body_pose(model: mujoco.MjModel, data: mujoco.MjData, name: str) -> np.ndarray:
    if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, name) >= 0:
        site = data.site(name)
        out = np.eye(4)
        out[:3, :3] = site.xmat.reshape(3, 3)
        out[:3, 3] = site.xpos
        return out
    return body_pose(model, data, name)


def check_hold(kit: Kit) -> list[Finding]:
    """Position servos hold each named pose under gravity within a few tenths of a degree,
    with no contact between the robot's own links on the way."""
    mj = load_mjcf(kit)
    if mj.nu == 0 or "floating_base" in kit.doc:  # a floating base: check/legged_check.py
        return []
    names = [j["name"] for j in kit.joints]
    acts = [mj.actuator(i).name for i in range(mj.nu)]
    qa = _qpos_indices(mj, names)
    findings = []
    for pose, q in kit.doc["poses"].items():
        data = mujoco.MjData(mj)
        data.qpos[qa] = q
        for name, value in zip(names, q, strict=True):
            if name in acts:
                data.ctrl[mj.actuator(name).id] = value
        mujoco.mj_forward(mj, data)
        contacts = int(data.ncon)
        steps = round(HOLD_SECONDS / mj.opt.timestep)
        for _ in range(steps):
            mujoco.mj_step(mj, data)
        error = np.degrees(np.abs(data.qpos[qa] - np.asarray(q)))
        findings.append(
            compare(
                "hold." + pose,
                f"servos hold '{pose}' for {HOLD_SECONDS:g} s",
                np.zeros_like(error),
                error,
                HOLD_TOLERANCE_DEG,
                "deg",
                names,
            )
        )
        findings.append(
            require("contact." + pose, contacts == 0, f"self-contacts at '{pose}': {contacts}")
        )
    return findings


def _movable(kit: Kit) -> list[dict]:
    return [j for j in kit.joints if j["type"] in ("revolute", "continuous", "prismatic")]


def check_parameters(kit: Kit) -> list[Finding]:
    """The MJCF carries robot.json's numbers (kit page, "Simulation parameters"): each joint's
    range, armature, damping and friction loss; each position servo's kp, kv, force range
    (drive_peak_torque_at_joint) and control range (the joint limits, radians); and contact
    exclusions between adjacent links only."""
    mj = load_mjcf(kit)
    joints = _movable(kit)
    missing = [j["name"] for j in joints if mujoco.mj_name2id(mj, _JOINT, j["name"]) < 0]
    if missing:
        return [require("mjcf.joints", False, f"joints missing from the MJCF: {missing}")]
    ids = [mj.joint(j["name"]).id for j in joints]
    dofs = [int(mj.jnt_dofadr[i]) for i in ids]
    limited = [(j, i) for j, i in zip(joints, ids, strict=True) if _is_limited(j)]
    findings = [
        compare(
            "mjcf.range",
            "joint ranges vs robot.json lower/upper",
            [[j["lower"], j["upper"]] for j, _ in limited],
            [mj.jnt_range[i] if mj.jnt_limited[i] else (np.nan, np.nan) for _, i in limited],
            PARAM_TOL,
            "rad or m",
            [j["name"] for j, _ in limited],
        ),
        compare(
            "mjcf.joint_dynamics",
            "armature, damping, friction loss vs robot.json",
            np.reshape([[j["armature"], j["damping"], j["friction"]] for j in joints], (-1, 3)),
            np.column_stack(
                [mj.dof_armature[dofs], mj.dof_damping[dofs], mj.dof_frictionloss[dofs]]
            ),
            PARAM_TOL,
            "SI",
            [j["name"] for j in joints],
        ),
        _excludes(kit, mj),
    ]
    servos = [a for a in kit.doc.get("actuators", []) if a.get("type") == "position"]
    if servos:
        findings.extend(_servos(kit, load_control_mjcf(kit), servos))
    return findings


def _is_limited(joint: dict) -> bool:
    return joint["type"] != "continuous" and joint["lower"] is not None


def _servos(kit: Kit, mj: mujoco.MjModel, servos: list[dict]) -> list[Finding]:
    """Position servos in the control MJCF vs robot.json `actuators` and joints."""
    joints = {j["name"]: j for j in kit.joints}
    names = [mj.actuator(i).name for i in range(mj.nu)]
    missing = [a["joint"] for a in servos if a["joint"] not in names]
    if missing:
        return [require("mjcf.servos", False, f"no position servo for {missing}")]
    acts = [mj.actuator(a["joint"]) for a in servos]
    on_joint = [
        int(act.trntype[0]) == mujoco.mjtTrn.mjTRN_JOINT
        and mj.joint(int(act.trnid[0])).name == a["joint"]
        for act, a in zip(acts, servos, strict=True)
    ]
    peak = [joints[a["joint"]]["drive_peak_torque_at_joint"] for a in servos]
    limited = [
        (a, act) for a, act in zip(servos, acts, strict=True) if _is_limited(joints[a["joint"]])
    ]
    return [
        require("mjcf.servos", all(on_joint), "each position servo drives its own joint"),
        compare(
            "mjcf.servo_gains",
            "servo kp, kv vs robot.json actuators",
            [[a["kp"], a["kv"]] for a in servos],
            # a position servo: gain kp; bias (0, -kp, -kv)
            [[act.gainprm[0], -act.biasprm[2]] for act in acts],
            PARAM_TOL,
            "N m/rad, N m s/rad",
            [a["joint"] for a in servos],
        ),
        compare(
            "mjcf.forcerange",
            "servo force range vs robot.json actuators and drive_peak_torque_at_joint",
            [[-a["forcerange"], a["forcerange"], -p, p] for a, p in zip(servos, peak, strict=True)],
            [
                [*act.forcerange, *act.forcerange] if act.forcelimited[0] else [np.nan] * 4
                for act in acts
            ],
            PARAM_TOL,
            "N m or N",
            [a["joint"] for a in servos],
        ),
        compare(
            "mjcf.ctrlrange",
            "servo control range (radians) vs robot.json joint limits",
            [[joints[a["joint"]]["lower"], joints[a["joint"]]["upper"]] for a, _ in limited],
            [act.ctrlrange if act.ctrllimited[0] else (np.nan, np.nan) for _, act in limited],
            PARAM_TOL,
            "rad or m",
            [a["joint"] for a, _ in limited],
        ),
    ]


def _excludes(kit: Kit, mj: mujoco.MjModel) -> Finding:
    """MJCF <exclude> pairs are exactly the links joined by a joint, plus the pairs robot.json
    lists as in contact in every configuration (`collision_pairs.always`), each of which
    must really touch (check/always.py), plus those the spec declares (`declared`: the
    source excludes them; the MJCF source check compares them with the source's)."""
    from simkit.check.always import not_touching

    links = {link["name"] for link in kit.doc["links"]}
    adjacent = {
        tuple(sorted((j["parent"], j["child"])))
        for j in kit.joints + kit.doc.get("fixed_joints", [])
        if j["parent"] in links and j["child"] in links
    }
    block = kit.doc.get("collision_pairs") or {}
    keys = ("always", "declared", "loop")  # loop: touching at home (check/loops.py)
    adjacent |= {tuple(sorted(p)) for key in keys for p in block.get(key, [])}
    adjacent |= {  # a loop closure joins its links as a joint does (robot.json `loops`)
        tuple(sorted((lp["link1"], lp["link2"])))
        for lp in kit.doc.get("loops", [])
        if lp["link1"] in links and lp["link2"] in links
    }
    apart = not_touching(kit, mj)
    if apart:
        return require("mjcf.excludes", False, f"excluded as always touching but apart: {apart}")
    excluded = set()
    for sig in mj.exclude_signature:
        a, b = int(sig) >> 16, int(sig) & 0xFFFF
        excluded.add(tuple(sorted((mj.body(a).name, mj.body(b).name))))
    extra, lacking = sorted(excluded - adjacent), sorted(adjacent - excluded)
    return require(
        "mjcf.excludes",
        not extra and not lacking,
        "contacts excluded between adjacent links only"
        + (f"; not adjacent but excluded: {extra}" if extra else "")
        + (f"; adjacent but not excluded: {lacking}" if lacking else ""),
    )
