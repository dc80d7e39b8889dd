"""Legged checks only on robots that stand (issue 32, class 7). Small URDFs made for the
purpose: a torso whose two arms hang below it at the zero pose, each ending in a two-finger
gripper (arms, not legs: fixed base); the same torso without grippers bolted to `world` by
a fixed joint (fixed base); a biped with its leg meshes missing, or with no geometry at all
(it stands on the boxes the import estimates), or with its boxes (floating, as before)."""

from __future__ import annotations

import pytest
import yaml

from simkit.importer import import_robot


def _link(name: str, geometry: str = '<box size="0.06 0.06 0.3"/>', mass: float = 2.0) -> str:
    at = '<origin xyz="0 0 -0.15"/>'
    return (
        f'<link name="{name}"><inertial>{at}<mass value="{mass:g}"/><inertia ixx="0.02" '
        f'iyy="0.02" izz="0.002" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<visual>{at}<geometry>{geometry}</geometry></visual>"
        f"<collision>{at}<geometry>{geometry}</geometry></collision></link>"
    )


def _joint(name: str, parent: str, child: str, xyz: str, kind: str = "revolute") -> str:
    limit = '<limit lower="-1" upper="1" effort="80" velocity="3"/>' if kind != "fixed" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="0 1 0"/>{limit}</joint>'
    )


def _robot(*parts: str) -> str:
    return '<?xml version="1.0"?>\n<robot name="rig">\n' + "\n".join(parts) + "\n</robot>\n"


def _bare(name: str) -> str:
    """A link of an inertial only: no `<visual>`, no `<collision>`."""
    return _link(name).split("<visual>")[0] + "</link>"


def _limbs(names: tuple[str, str], fingers: bool, legs: str = "boxes") -> list[str]:
    """Two limbs of upper, lower and end links hanging 0.9 m below the root `torso`; `legs`:
    their geometry, "boxes", "missing" meshes or "none" (inertials only)."""
    parts = []
    for side, y in (("l", 0.15), ("r", -0.15)):
        upper, lower = f"{side}_{names[0]}", f"{side}_{names[1]}"
        for name in (upper, lower, f"{side}_end"):
            mesh = f'<mesh filename="meshes/{name}.stl"/>'
            made = {"boxes": _link(name), "missing": _link(name, mesh), "none": _bare(name)}
            parts.append(made[legs])
        parts += [
            _joint(f"{side}_1", "torso", upper, f"0 {y} -0.1"),
            _joint(f"{side}_2", upper, lower, "0 0 -0.3"),
            _joint(f"{side}_3", lower, f"{side}_end", "0 0 -0.3"),
        ]
        if fingers:
            for finger, x in (("a", 0.02), ("b", -0.02)):
                name = f"{side}_finger_{finger}"
                parts.append(_link(name, '<box size="0.01 0.01 0.05"/>', 0.05))
                parts.append(_joint(f"{name}_joint", f"{side}_end", name, f"{x} 0 -0.3"))
    return parts


TORSO = _link("torso", '<box size="0.2 0.4 0.2"/>', 10.0).replace("-0.15", "0")


def _base(tmp_path, text: str) -> tuple[bool, str]:
    urdf = tmp_path / "rig.urdf"
    urdf.write_text(text)
    done = import_robot(urdf, tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    line = next(x for x in done.lines if " base" in x and "robot[rig]" in x)
    return bool(spec.get("floating_base")), line


def test_two_arms_with_grippers_hanging_below_the_torso_are_no_legs(tmp_path):
    floating, line = _base(tmp_path, _robot(TORSO, *_limbs(("upper_arm", "forearm"), True)))
    assert not floating and "2 of 2 limbs" in line and "2 of them branch into fingers" in line


def test_a_robot_bolted_to_world_by_a_fixed_joint_is_fixed(tmp_path):
    world = ['<link name="world"/>', _joint("mount", "world", "torso", "0 0 0", "fixed")]
    floating, line = _base(tmp_path, _robot(*world, TORSO, *_limbs(("upper", "lower"), False)))
    assert not floating and "bolts the robot to 'world' with a fixed joint" in line


def test_a_biped_whose_leg_meshes_are_missing_stands_on_estimated_boxes(tmp_path):
    floating, line = _base(tmp_path, _robot(TORSO, *_limbs(("thigh", "shin"), False, "missing")))
    assert floating and "floating base: 2 limbs reach" in line


def test_a_biped_with_its_geometry_still_floats(tmp_path):
    floating, line = _base(tmp_path, _robot(TORSO, *_limbs(("thigh", "shin"), False)))
    assert floating and "floating base: 2 limbs reach" in line


@pytest.mark.slow
@pytest.mark.parametrize(
    ("torso", "limbs", "legged"),
    [
        (TORSO, (("upper_arm", "forearm"), True, "boxes"), False),
        (_bare("torso"), (("a", "b"), False, "none"), True),
    ],
)
def test_the_rig_and_a_biped_without_geometry_build_and_pass_their_checks(
    tmp_path, torso, limbs, legged
):
    from simkit.pipeline import build

    urdf = tmp_path / "rig.urdf"
    urdf.write_text(_robot(torso, *_limbs(*limbs)))
    done = import_robot(urdf, tmp_path / "out")
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert result.findings and all(f.ok for f in result.findings)
    assert any(f.check.startswith("legged.") for f in result.findings) is legged
