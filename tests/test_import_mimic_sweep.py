"""Mimic joints move together in the self-collision sweep and the named poses (issue 32,
class 8): two parallel bars of a four-bar linkage, the second a mimic of the first, never
meet when they move together; swept alone, the first would swing into the second, a
configuration the mechanism never reaches. The URDF gives no position limits, so the import
estimates them (narrowed where the bars, moving together, meet the palm) and the check
sweeps them whole: the kit built from it passes its checks (it failed two sweeps before)."""

from __future__ import annotations

import yaml

from simkit.importer import import_robot

BAR = '<geometry><box size="0.01 0.01 0.1"/></geometry>'


def _link(name: str, shape: str = BAR) -> str:
    return (
        f'<link name="{name}"><inertial><origin xyz="0 0 0.05"/><mass value="0.1"/>'
        '<inertia ixx="0.0001" iyy="0.0001" izz="0.00001" ixy="0" ixz="0" iyz="0"/>'
        f'</inertial><visual><origin xyz="0 0 0.05"/>{shape}</visual>'
        f'<collision><origin xyz="0 0 0.05"/>{shape}</collision></link>'
    )


def _bar(name: str, x: float, mimic: str = "") -> str:
    return (
        f'<joint name="{name}_hinge" type="revolute"><parent link="palm"/>'
        f'<child link="{name}"/><origin xyz="{x} 0 0.03"/><axis xyz="0 1 0"/>'
        f'<limit effort="5" velocity="2"/>{mimic}</joint>'
    )


URDF = "\n".join(
    [
        '<?xml version="1.0"?>',
        '<robot name="linkage">',
        _link("palm", '<geometry><box size="0.1 0.05 0.02"/></geometry>').replace(
            'xyz="0 0 0.05"', 'xyz="0 0 0"'
        ),
        _link("front"),
        _link("back"),
        _bar("front", 0.0),
        _bar("back", 0.025, '<mimic joint="front_hinge" multiplier="1" offset="0"/>'),
        "</robot>",
    ]
)


def test_a_mimic_joint_moves_with_its_leader_in_the_sweeps(tmp_path):
    from simkit.pipeline import build

    urdf = tmp_path / "linkage.urdf"
    urdf.write_text(URDF + "\n")
    done = import_robot(urdf, tmp_path / "out", floating=False)
    spec = yaml.safe_load(done.spec_path.read_text())
    back = next(j for j in spec["joints"] if j["name"] == "back_hinge")
    assert back["mimic"]["joint"] == "front_hinge"
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    checks = {f.check: f for f in result.findings}
    assert checks["self_collision.sweep.front_hinge"].ok  # the back bar swings with it
    assert "self_collision.sweep.back_hinge" not in checks  # moved by its leader's sweep
    assert checks["self_collision.poses"].ok
    robot = result.kit_dir / "robot.json"
    ranges = {
        r["joint"]: r
        for r in yaml.safe_load(robot.read_text())["geometry"]["self_collision"]["free_ranges"]
    }
    front, back = ranges["front_hinge"], ranges["back_hinge"]
    assert front["upper"] > 0.5  # alone, the front bar meets the back one at 0.15 rad
    assert (back["lower"], back["upper"]) == (front["lower"], front["upper"])  # its leader's
