"""A GPU scene never fails a build (issue 42, class 9).

A family of imported 74-joint humanoids with 146 collision geoms built before GPU scenes
existed, then failed: some GPU scenes did not load in C MuJoCo ("Could not allocate memory":
1,489 explicit pairs, `<size nconmax="5956" njmax="23898">`). Now MuJoCo Warp's sizes are
custom numerics (C MuJoCo sizes its own arena), the explicit pairs are capped, and where a
robot cannot have a GPU scene the kit says so in one line and builds. A humanoid made for the
purpose: 43 joints (legs, waist, neck, arms, three two-joint fingers a hand), 44 links with
three collision spheres each (132 collision geoms), standing on box-shaped feet."""

from __future__ import annotations

import json

import mujoco
import pytest

from simkit.importer import import_robot
from simkit.pipeline import build

pytestmark = pytest.mark.slow

SPHERES = 3  # collision spheres a link
RADIUS = 0.035  # m


def _link(name: str, tip: tuple[float, float, float], mass: float = 1.0) -> str:
    """A link whose spheres run from its origin to `tip` (m, link frame), their radius at most
    a quarter of the link's length (short links do not reach their neighbours' neighbours)."""
    radius = min(RADIUS, 0.25 * sum(c * c for c in tip) ** 0.5)
    spheres = "".join(
        f'<collision><origin xyz="{" ".join(f"{c * i / (SPHERES - 1):.4f}" for c in tip)}"/>'
        f'<geometry><sphere radius="{radius:.4f}"/></geometry></collision>'
        for i in range(SPHERES)
    )
    half = " ".join(f"{c / 2:.4f}" for c in tip)
    return (
        f'<link name="{name}"><inertial><origin xyz="{half}"/><mass value="{mass}"/>'
        '<inertia ixx="0.005" iyy="0.005" izz="0.005" ixy="0" ixz="0" iyz="0"/></inertial>'
        f'<visual><origin xyz="{half}"/><geometry><sphere radius="{radius:.4f}"/></geometry>'
        f"</visual>{spheres}</link>"
    )


def _joint(name: str, parent: str, xyz: str, axis: str, limit: float = 1.0) -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{name}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
        f'<limit lower="-{limit}" upper="{limit}" effort="300" velocity="3"/></joint>'
    )


def _chain(parent: str, joints: list[tuple[str, str, str, tuple]]) -> list[str]:
    """Links and joints of a serial chain: (name, origin in the parent, axis, tip)."""
    out = []
    for name, xyz, axis, tip in joints:
        out += [_link(name, tip), _joint(name, parent, xyz, axis)]
        parent = name
    return out


def _foot(side: str) -> str:
    """A box foot (and its three spheres) below the ankle."""
    box = '<box size="0.22 0.1 0.04"/>'
    return (
        f'<link name="{side}_foot"><inertial><origin xyz="0.03 0 -0.05"/><mass value="1"/>'
        '<inertia ixx="0.005" iyy="0.005" izz="0.005" ixy="0" ixz="0" iyz="0"/></inertial>'
        f'<visual><origin xyz="0.03 0 -0.05"/><geometry>{box}</geometry></visual>'
        f'<collision><origin xyz="0.03 0 -0.05"/><geometry>{box}</geometry></collision></link>'
        f'<joint name="{side}_ankle_pitch" type="revolute"><parent link="{side}_ankle"/>'
        f'<child link="{side}_foot"/><origin xyz="0 0 -0.02"/><axis xyz="0 1 0"/>'
        '<limit lower="-0.6" upper="0.6" effort="300" velocity="3"/></joint>'
    )


def humanoid() -> str:
    parts = [_link("pelvis", (0.0, 0.0, 0.1), 5.0)]
    parts += _chain(
        "pelvis",
        [
            ("waist_yaw", "0 0 0.12", "0 0 1", (0, 0, 0.03)),
            ("waist_roll", "0 0 0.03", "1 0 0", (0, 0, 0.03)),
            ("torso", "0 0 0.03", "0 1 0", (0, 0, 0.4)),
            ("neck_yaw", "0 0 0.42", "0 0 1", (0, 0, 0.05)),
            ("head", "0 0 0.05", "0 1 0", (0.05, 0, 0.12)),
        ],
    )
    for side, y in (("left", 1), ("right", -1)):
        parts += _chain(
            "torso",
            [
                (f"{side}_shoulder_pitch", f"0 {0.24 * y} 0.36", "0 1 0", (0, 0.04 * y, 0)),
                (f"{side}_shoulder_roll", f"0 {0.04 * y} 0", "1 0 0", (0, 0, -0.04)),
                (f"{side}_upper_arm", "0 0 -0.04", "0 0 1", (0, 0, -0.24)),
                (f"{side}_elbow", "0 0 -0.26", "0 1 0", (0, 0, -0.22)),
                (f"{side}_wrist_yaw", "0 0 -0.24", "0 0 1", (0, 0, -0.03)),
                (f"{side}_wrist_pitch", "0 0 -0.03", "0 1 0", (0, 0, -0.03)),
                (f"{side}_hand", "0 0 -0.03", "1 0 0", (0, 0, -0.08)),
            ],
        )
        for finger, x in (("index", 0.08), ("middle", 0.0), ("ring", -0.08)):
            parts += _chain(
                f"{side}_hand",
                [
                    (f"{side}_{finger}_1", f"{x} 0 -0.09", "0 1 0", (0, 0, -0.04)),
                    (f"{side}_{finger}_2", "0 0 -0.045", "0 1 0", (0, 0, -0.03)),
                ],
            )
        parts += _chain(
            "pelvis",
            [
                (f"{side}_hip_yaw", f"0 {0.1 * y} -0.02", "0 0 1", (0, 0, -0.04)),
                (f"{side}_hip_roll", "0 0 -0.05", "1 0 0", (0, 0, -0.04)),
                (f"{side}_thigh", "0 0 -0.05", "0 1 0", (0, 0, -0.38)),
                (f"{side}_shin", "0 0 -0.4", "0 1 0", (0, 0, -0.38)),
                (f"{side}_ankle", "0 0 -0.4", "1 0 0", (0, 0, -0.02)),
            ],
        )
        parts.append(_foot(side))
    return '<robot name="big_humanoid">' + "".join(parts) + "</robot>"


def test_a_large_humanoid_builds_and_says_which_gpu_scene_it_has(tmp_path):
    path = tmp_path / "big_humanoid.urdf"
    path.write_text(humanoid())
    done = import_robot(path, tmp_path / "spec", floating=True)
    kit = build(str(done.spec_path), tmp_path / "kits").kit_dir  # a GPU scene never fails it
    doc = json.loads((kit / "robot.json").read_text())
    assert len(doc["joints"]) >= 40
    block = doc["gpu_scene"]
    readme = (kit / "README.md").read_text()
    if block["file"] is None:  # no GPU scene: one line in robot.json and the README says why
        assert block["note"].startswith("no GPU scene: ") and "\n" not in block["note"]
        assert block["note"] in readme and "mjcf_mjx" not in doc["files"]
        return
    gpu = mujoco.MjModel.from_xml_path(str(kit / block["file"]))  # C MuJoCo allocates it
    assert gpu.ngeom > 100 and gpu.npair == block["pairs"] <= 512
    mujoco.mj_step(gpu, mujoco.MjData(gpu))
    assert gpu.nconmax == -1 and gpu.njmax == -1  # Warp's sizes are custom numerics
    assert f"`warp_nconmax` {block['nconmax']}" in readme
