"""Underactuated grippers with mimic chains and passive joints (issue 32, class 6d): a
three-finger gripper made for the purpose. Each finger's spread joint follows the first
finger's (one with multiplier -1), its middle joint mimics its knuckle with an offset, and
its tip mimics the middle joint (a mimic of a mimic, which URDF readers resolve
differently); a second variant has passive zero-range tips (effort and velocity 0). The
import rewrites each chain to follow the first leader (the same motion, one line each), and
the kits pass every check (the chained gripper failed the URDF FK check before)."""

from __future__ import annotations

import math

import pytest
import yaml

from simkit.importer import import_robot


def _box(name: str, size: tuple[float, float, float], mass: float) -> str:
    sx, sy, sz = size
    box = f'<geometry><box size="{sx} {sy} {sz}"/></geometry>'
    at = f'<origin xyz="0 0 {sz / 2:g}"/>'
    inertia = " ".join(
        f'{k}="{mass / 12 * v:.3g}"'
        for k, v in (
            ("ixx", sy * sy + sz * sz),
            ("iyy", sx * sx + sz * sz),
            ("izz", sx * sx + sy * sy),
        )
    )
    return (
        f'<link name="{name}"><inertial>{at}<mass value="{mass:g}"/><inertia {inertia} '
        f'ixy="0" ixz="0" iyz="0"/></inertial><visual>{at}{box}</visual>'
        f"<collision>{at}{box}</collision></link>"
    )


def _joint(name: str, parent: str, child: str, at: str, axis: str, limit: str, mimic=None) -> str:
    follow = (
        f'<mimic joint="{mimic[0]}" multiplier="{mimic[1]:g}" offset="{mimic[2]:g}"/>'
        if mimic
        else ""
    )
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'{at}<axis xyz="{axis}"/><limit {limit}/>{follow}</joint>'
    )


def gripper(passive_tips: bool) -> str:
    """The URDF: a palm and three fingers of base, knuckle, middle and tip links."""
    parts = [_box("palm", (0.1, 0.1, 0.04), 0.6)]
    for i, turn in enumerate((0.0, 2 * math.pi / 3, 4 * math.pi / 3), 1):
        f = f"f{i}"
        x, y = 0.035 * math.cos(turn), 0.035 * math.sin(turn)
        parts += [
            _box(f"{f}_base", (0.02, 0.02, 0.01), 0.02),
            _box(f"{f}_prox", (0.015, 0.015, 0.045), 0.04),
            _box(f"{f}_mid", (0.015, 0.015, 0.035), 0.03),
            _box(f"{f}_tip", (0.012, 0.012, 0.025), 0.02),
        ]
        spread = None if i == 1 else ("f1_spread", -1.0 if i == 2 else 1.0, 0.0)
        at = f'<origin xyz="{x:.4f} {y:.4f} 0.04" rpy="0 0 {turn:.4f}"/>'
        parts.append(
            _joint(f"{f}_spread", "palm", f"{f}_base", at, "0 0 1",
                   'lower="-0.3" upper="0.3" effort="2" velocity="1"', spread)
        )  # fmt: skip
        parts.append(
            _joint(f"{f}_j1", f"{f}_base", f"{f}_prox", '<origin xyz="0 0 0.01"/>', "0 1 0",
                   'lower="-0.2" upper="1.2" effort="5" velocity="2"')
        )  # fmt: skip
        parts.append(
            _joint(f"{f}_j2", f"{f}_prox", f"{f}_mid", '<origin xyz="0 0 0.045"/>', "0 1 0",
                   'lower="0" upper="1.5" effort="5" velocity="2"', (f"{f}_j1", 0.8, 0.1))
        )  # fmt: skip
        tip = (
            ('lower="0" upper="0" effort="0" velocity="0"', None)
            if passive_tips
            else ('lower="-0.5" upper="0.5" effort="0" velocity="0"', (f"{f}_j2", 0.5, 0.0))
        )
        parts.append(
            _joint(f"{f}_j3", f"{f}_mid", f"{f}_tip", '<origin xyz="0 0 0.035"/>', "0 1 0", *tip)
        )
    return '<?xml version="1.0"?>\n<robot name="gripper">\n' + "\n".join(parts) + "\n</robot>\n"


def _imported(tmp_path, passive_tips: bool):
    urdf = tmp_path / "gripper.urdf"
    urdf.write_text(gripper(passive_tips))
    return import_robot(urdf, tmp_path / "out")


def test_a_mimic_of_a_mimic_follows_the_first_leader(tmp_path):
    done = _imported(tmp_path, passive_tips=False)
    joints = {j["name"]: j for j in yaml.safe_load(done.spec_path.read_text())["joints"]}
    tip = joints["f2_j3"]["mimic"]
    assert tip["joint"] == "f2_j1"  # not f2_j2, itself a mimic
    assert tip["multiplier"] == pytest.approx(0.4) and tip["offset"] == pytest.approx(0.05)
    leaders = {j["mimic"]["joint"] for j in joints.values() if "mimic" in j}
    assert not any("mimic" in joints[name] for name in leaders)
    assert "itself a mimic: follows 'f2_j1' x 0.4 + 0.05" in "\n".join(done.lines)


@pytest.mark.slow
@pytest.mark.parametrize("passive_tips", [False, True])
def test_the_gripper_kit_passes_every_check(tmp_path, passive_tips):
    from simkit.pipeline import build

    done = _imported(tmp_path, passive_tips)
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert result.findings and all(f.ok for f in result.findings)
