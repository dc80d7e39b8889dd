"""The GPU scene's stand-in box for a cylinder that meets a box (MJX has no cylinder-box
collision; issue 30): the circumscribed box, unless it would touch its partner at a named pose
where the cylinder does not. There it would push where the main MJCF has no contact (an
imported two-arm torso's shoulder cylinder, 1 cm into the torso's box at home, held the arm
0.2 m apart), so the inscribed box stands in. A small URDF made for the purpose: a cylinder
on the second link of a bent chain whose base carries a box diagonally beside it at home
(the cylinder's axis at the base's origin), within the chain's reach."""

from __future__ import annotations

import math

import pytest

from simkit.importer import import_robot
from simkit.pipeline import build, model_from_spec

pytestmark = pytest.mark.slow

INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
    'iyz="0"/></inertial>'
)


def _link(name: str, geometry: str, xyz: str) -> str:
    placed = f'<origin xyz="{xyz}"/><geometry>{geometry}</geometry>'
    shapes = f"<visual>{placed}</visual><collision>{placed}</collision>"
    return f'<link name="{name}">{INERTIAL}{shapes}</link>'


def _joint(name: str, parent: str, child: str, xyz: str) -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="0 0 1"/>'
        '<limit lower="-1.5" upper="1.5" effort="50" velocity="2"/></joint>'
    )


def _urdf(corner: float) -> str:
    """The box's near corner at (corner, corner) from the cylinder's axis at home (m)."""
    centre = corner + 0.05
    return (
        '<robot name="stand_in">'
        + _link("base", '<box size="0.1 0.1 0.1"/>', f"{centre} {centre} 0.05")
        + _link("arm", '<sphere radius="0.02"/>', "0 0 0.05")
        + _link("hand", '<cylinder radius="0.05" length="0.1"/>', "-0.15 0.25 0.05")
        + _joint("j1", "base", "arm", "0 -0.25 0")
        + _joint("j2", "arm", "hand", "0.15 0 0")
        + "</robot>"
    )


def _plan(tmp_path, corner: float):
    path = tmp_path / f"stand_in_{round(corner * 1000)}.urdf"
    path.write_text(_urdf(corner))
    done = import_robot(path, tmp_path / path.stem, floating=False)
    return done, model_from_spec(str(done.spec_path)).products.gpu_scene


def _hand(plan) -> dict:
    return next(g for g in plan["colliders"] if g["link"] == "hand")


def test_a_box_beside_the_cylinder_at_home_gets_the_inscribed_stand_in(tmp_path):
    # the corner 6.6 mm from the cylinder's surface, inside its circumscribed box
    done, plan = _plan(tmp_path, 0.04)
    hand = _hand(plan)
    assert hand["kind"] == "cylinder" and hand["box_for"]
    assert hand["box_half"] == pytest.approx(0.05 / math.sqrt(2))
    result = build(str(done.spec_path), tmp_path / "kits")  # the gpu_scene check holds home
    assert result.kit_dir.is_dir()


def test_a_box_clear_of_the_circumscribed_box_keeps_it(tmp_path):
    _done, plan = _plan(tmp_path, 0.06)  # the corner clear of the circumscribed box
    hand = _hand(plan)
    assert hand["box_for"] and hand["box_half"] == pytest.approx(0.05)
