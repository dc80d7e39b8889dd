"""The USD's poses vs MuJoCo: every link and the tool frame composed from the USD joints at
q = 0 and seeded random configurations, and the authored Xforms vs the joints at q = 0."""

from __future__ import annotations

import mujoco
import numpy as np

from simkit.check.findings import Finding, compare
from simkit.check.kit import Kit
from simkit.check.mujoco import body_pose, site_or_body_pose
from simkit.check.readers.usd import UsdKinematics, prim_name

N_RANDOM = 25
SEED = 1
#: Tool pose through 6+ float32 joint frames: metres, and rotation-matrix entries.
FK_TOL_M = 1e-6
FK_TOL_ROT = 1e-6


def fk_findings(kit: Kit, mj, kin: UsdKinematics, paths: dict[str, str]) -> list[Finding]:
    """T_base_tool and T_base_link of every link, composed from the USD joints, vs MuJoCo at
    q = 0 and seeded random configurations; and the authored Xforms vs the joints at q = 0."""
    tool, base = kit.doc.get("tool_frame"), kit.base_frame
    links = [link["name"] for link in kit.doc["links"]]
    targets = links + ([tool] if tool and tool in paths else [])
    joints = [j for j in kit.joints if j["type"] in ("revolute", "continuous", "prismatic")]
    rng = np.random.default_rng(SEED)
    lower = [j["lower"] if j["lower"] is not None else -np.pi for j in joints]
    upper = [j["upper"] if j["upper"] is not None else np.pi for j in joints]
    configs = np.vstack([np.zeros(len(joints)), rng.uniform(lower, upper, (N_RANDOM, len(joints)))])
    data = mujoco.MjData(mj)
    qadr = [int(mj.jnt_qposadr[mj.joint(j["name"]).id]) for j in joints]
    exp, act = [], []
    for q in configs:
        data.qpos[qadr] = q
        mujoco.mj_kinematics(mj, data)
        inv = np.linalg.inv(body_pose(mj, data, base))
        exp.append([inv @ site_or_body_pose(mj, data, t) for t in targets])
        poses = kin.poses({prim_name(j["name"]): v for j, v in zip(joints, q, strict=True)})
        inv = np.linalg.inv(kin.pose(poses, paths[base]))
        act.append([inv @ kin.pose(poses, paths[t]) for t in targets])
    exp, act = np.array(exp), np.array(act)
    rest = kin.poses({})
    label = f"in {base} at q = 0 and {N_RANDOM} random configurations, from the USD joints"
    findings = [
        compare(
            "usd.fk.links",
            f"every link pose {label}",
            exp[:, : len(links), :3],
            act[:, : len(links), :3],
            FK_TOL_M,
            "m or 1",
        ),
        compare(
            "usd.xforms",
            "authored link Xforms vs the joints composed at q = 0",
            [kin.world[paths[n]] for n in links],
            [rest[paths[n]] for n in links],
            1e-6,
            "m or 1",
        ),
    ]
    if len(targets) > len(links):
        findings += [
            compare(
                "usd.fk",
                f"{tool} position {label}",
                exp[:, -1, :3, 3],
                act[:, -1, :3, 3],
                FK_TOL_M,
                "m",
            ),
            compare(
                "usd.fk.rotation",
                f"{tool} rotation {label}",
                exp[:, -1, :3, :3],
                act[:, -1, :3, :3],
                FK_TOL_ROT,
                "",
            ),
        ]
    return findings
