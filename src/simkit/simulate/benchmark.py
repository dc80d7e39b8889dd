"""Inverse dynamics of the benchmark cycles on the kit's written MJCF (kit page
000_5f76ade803e16979.txt, "Benchmark cycle"): the most torque each joint of the kit's MuJoCo
model needs to follow each cycle with its payload, and its fraction of the actuator's
forcerange. robot.json `benchmarks.kit_model_check` (1 kg cycle, the trajectory files) and
`benchmarks.rated_cycle_torque` (rated payload) come from here."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from simkit.kitio import layout
from simkit.kitio.fmt import vec
from simkit.model.robot import Robot

#: Name of the body that carries the payload in the inverse-dynamics model.
PAYLOAD_BODY = "simkit_payload"


def inverse_dynamics_model(mjcf_text: str, parent_body: str, payload: dict):
    """The kit's MJCF with its geometry left out (contacts play no part; every body has an
    explicit inertial) and the payload attached to `parent_body` as one body."""
    import mujoco

    root = ET.fromstring(mjcf_text)
    for parent in list(root.iter()):
        for child in list(parent):
            if child.tag == "geom" or (child.tag == "mesh" and parent.tag == "asset"):
                parent.remove(child)
    body = next(b for b in root.iter("body") if b.get("name") == parent_body)
    if payload["mass"] > 0:
        holder = ET.SubElement(body, "body", name=PAYLOAD_BODY, pos=vec(payload["com_link"]))
        ET.SubElement(
            holder,
            "inertial",
            pos="0 0 0",
            mass=vec([payload["mass"]]),
            diaginertia=vec(payload["inertia_diag"]),
        )
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    return model


def kit_model_check(
    mjcf_text: str,
    joints: list[str],
    parent_body: str,
    payload: dict,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
) -> dict:
    """Largest |torque| (N m) each joint of the MJCF needs to follow (q, qd, qdd) with the
    payload (MuJoCo inverse dynamics: mass matrix, bias, damping), and its fraction of the
    actuator's forcerange."""
    import mujoco

    model = inverse_dynamics_model(mjcf_text, parent_body, payload)
    data = mujoco.MjData(model)
    qadr = [int(model.jnt_qposadr[model.joint(n).id]) for n in joints]
    dadr = [int(model.jnt_dofadr[model.joint(n).id]) for n in joints]
    peak = np.zeros(len(joints))
    for row in range(len(q)):
        data.qpos[qadr], data.qvel[dadr], data.qacc[dadr] = q[row], qd[row], qdd[row]
        mujoco.mj_inverse(model, data)
        peak = np.maximum(peak, np.abs(data.qfrc_inverse[dadr]))
    limit = np.array([float(model.actuator(n).forcerange[1]) for n in joints])
    return {
        "joints": joints,
        "max_torque": list(peak),
        "forcerange": list(limit),
        "fraction": list(peak / limit),
    }


def run(kit_dir: Path, robot: Robot) -> dict | None:
    """{cycle name: kit_model_check result} for an arm with benchmark cycles, else None."""
    samples = robot.products.benchmark_cycles
    if not samples:
        return None
    text = (kit_dir / layout.mjcf(robot.name)).read_text(encoding="utf-8")
    return {
        name: kit_model_check(
            text, samples["joints"], samples["link"], c["payload"], c["q"], c["qd"], c["qdd"]
        )
        for name, c in samples["cycles"].items()
    }
