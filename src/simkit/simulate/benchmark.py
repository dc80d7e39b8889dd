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


def inverse_dynamics_model(
    mjcf_text: str, parent_body: str, payload: dict, assets: dict[str, bytes] | None = None
):
    """The kit's MJCF with the payload attached to `parent_body` as one body.

    With `assets` (mesh bytes keyed by path under the MJCF's meshdir) the model keeps its
    geometry and contacts, as the kit's MJCF has them on (issue 12): a trajectory that drives
    links into each other then needs the contact forces too. Without, the geometry is left out
    (every body has an explicit inertial) and contacts are off: enough for poses at rest."""
    import mujoco

    root = ET.fromstring(mjcf_text)
    if assets is None:
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
    text = ET.tostring(root, encoding="unicode")
    if assets is not None:
        return mujoco.MjModel.from_xml_string(text, assets)
    model = mujoco.MjModel.from_xml_string(text)
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
    assets: dict[str, bytes],
) -> dict:
    """Largest |torque| (N m) each joint of the MJCF needs to follow (q, qd, qdd) with the
    payload (MuJoCo inverse dynamics: mass matrix, bias, damping and contact forces, with the
    MJCF's own collision geometry and excludes; `assets`: its meshes), and its fraction of the
    actuator's forcerange."""
    import mujoco

    model = inverse_dynamics_model(mjcf_text, parent_body, payload, assets)
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
        "contacts": "on: the MJCF's collision geometry and contact excludes, as in the kit",
    }


def run(kit_dir: Path, robot: Robot) -> dict | None:
    """{cycle name: kit_model_check result} for an arm with benchmark cycles, else None."""
    samples = robot.products.benchmark_cycles
    if not samples:
        return None
    text = (kit_dir / layout.mjcf(robot.name)).read_text(encoding="utf-8")
    assets = mesh_assets(kit_dir)
    return {
        name: kit_model_check(
            text,
            samples["joints"],
            samples["link"],
            c["payload"],
            c["q"],
            c["qd"],
            c["qdd"],
            assets,
        )
        for name, c in samples["cycles"].items()
    }


def mesh_assets(kit_dir: Path) -> dict[str, bytes]:
    """The kit's mesh files keyed by their path under `meshes/` (the MJCF's meshdir), so the
    MJCF compiles from a string with its collision geometry."""
    meshes = kit_dir / "meshes"
    files = sorted(f for f in meshes.rglob("*") if f.suffix in (".stl", ".obj"))
    return {f.relative_to(meshes).as_posix(): f.read_bytes() for f in files}
