"""Issue 42, class 1: point contacts. A floating biped whose feet touch the world only
through zero-radius collision spheres at their four corners (the "minimal contact" idiom:
the other links have visuals and no collision, the feet's visual meshes are not in the download).
Each point becomes a collision sphere centred on it, of radius 0.05 x the largest distance
between the link's points, at least 5 mm (importer/translate/points.py), marked estimated
in the spec and reported in one line; the kit then stands on its points."""

from __future__ import annotations

import pytest
import yaml

from simkit.importer import import_robot
from simkit.importer.translate.points import FLOOR, SPAN_FRACTION

BOX = '<geometry><box size="{}"/></geometry>'


def _inertial(mass: float, i: float) -> str:
    return (
        f'<inertial><mass value="{mass}"/><inertia ixx="{i}" iyy="{i}" izz="{i}" '
        'ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def _corners(x: float, y: float, z: float) -> str:
    return "".join(
        f'<collision><origin xyz="{sx * x} {sy * y} {z}"/>'
        '<geometry><sphere radius="0.0"/></geometry></collision>'
        for sx in (-1, 1)
        for sy in (-1, 1)
    )


def _leg(side: str, y: float) -> str:
    limit = '<limit lower="-1" upper="1" effort="80" velocity="5"/>'
    return f"""
  <joint name="{side}_hip" type="revolute"><parent link="pelvis"/><child link="{side}_thigh"/>
    <origin xyz="0 {y} -0.05"/><axis xyz="0 1 0"/>{limit}</joint>
  <link name="{side}_thigh">{_inertial(2.0, 0.02)}
    <visual><origin xyz="0 0 -0.15"/>{BOX.format("0.06 0.06 0.3")}</visual></link>
  <joint name="{side}_knee" type="revolute"><parent link="{side}_thigh"/>
    <child link="{side}_shin"/><origin xyz="0 0 -0.3"/><axis xyz="0 1 0"/>{limit}</joint>
  <link name="{side}_shin">{_inertial(1.5, 0.015)}
    <visual><origin xyz="0 0 -0.15"/>{BOX.format("0.05 0.05 0.3")}</visual></link>
  <joint name="{side}_ankle" type="revolute"><parent link="{side}_shin"/>
    <child link="{side}_foot"/><origin xyz="0 0 -0.3"/><axis xyz="0 1 0"/>{limit}</joint>
  <link name="{side}_foot">{_inertial(0.5, 0.002)}
    <visual><geometry><mesh filename="foot.stl"/></geometry></visual>
    {_corners(0.1, 0.05, -0.05)}</link>"""


URDF = f"""<robot name="pointfoot">
  <link name="pelvis">{_inertial(8.0, 0.1)}
    <visual>{BOX.format("0.2 0.3 0.1")}</visual></link>{_leg("left", 0.1)}{_leg("right", -0.1)}
</robot>
"""
#: m: largest distance between a foot's corner points (0.2 x 0.1 m)
SPAN = (0.2**2 + 0.1**2) ** 0.5


def _import(tmp_path):
    path = tmp_path / "src" / "pointfoot.urdf"
    path.parent.mkdir()
    path.write_text(URDF)
    return import_robot(path, tmp_path / "spec", floating=True)


def test_each_point_is_a_sphere_of_the_stated_radius(tmp_path):
    done = _import(tmp_path)
    spec = yaml.safe_load(done.spec_path.read_text())
    foot = next(link for link in spec["links"] if link["name"] == "left_foot")
    spheres = foot["collision_primitives"]
    radius = max(FLOOR, round(SPAN_FRACTION * SPAN, 6))
    assert len(spheres) == 4 and radius > FLOOR
    assert all(s["shape"] == "sphere" and s["radius"] == pytest.approx(radius) for s in spheres)
    assert "collision_primitives" in foot["estimated"]
    lines = [line for line in done.lines if "contact points" in line]
    assert len(lines) == 2, lines  # one per foot


@pytest.mark.slow
def test_the_biped_stands_on_its_points(tmp_path):
    from simkit.pipeline import build

    kit = build(str(_import(tmp_path).spec_path), tmp_path / "kits").kit_dir
    assert (kit / "robot.json").is_file()  # the build's checks (drop and stand) passed
