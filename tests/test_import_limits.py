"""Estimated position limits are narrowed to the range free of self-contact (fixups/limits.py);
published limits are kept. The truth here is geometry by hand: a bar turning over a slab it is
not joined to (a post between them: joined links never collide in a kit)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from simkit.importer import import_robot
from simkit.spec.validate import load_spec

SLAB_TOP = 0.05  # m: the base slab's top face (slab 0.6 x 0.6 x 0.1 about the origin)
PIVOT = 0.1  # m: joint height
BAR = (0.04, 0.2)  # m: bar thickness and length, from the pivot up at 0 rad


def _urdf(limit: str) -> str:
    inertia = '<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/>'
    bar = f'<box size="{BAR[0]} {BAR[0]} {BAR[1]}"/>'
    slab = '<box size="0.6 0.6 0.1"/>'
    return (
        '<?xml version="1.0"?>\n<robot name="bar">'
        f'<link name="base"><inertial><mass value="5"/>{inertia}</inertial>'
        f"<visual><geometry>{slab}</geometry></visual>"
        f"<collision><geometry>{slab}</geometry></collision></link>"
        f'<link name="post"><inertial><mass value="0.1"/>{inertia}</inertial>'
        '<visual><origin xyz="0 0 0.02"/><geometry><box size="0.02 0.02 0.02"/></geometry>'
        '</visual><collision><origin xyz="0 0 0.02"/><geometry><box size="0.02 0.02 0.02"/>'
        "</geometry></collision></link>"
        '<joint name="lift" type="revolute"><parent link="base"/><child link="post"/>'
        '<origin xyz="0 0 0.06"/><axis xyz="1 0 0"/>'
        '<limit lower="-0.05" upper="0.05" effort="5" velocity="2"/></joint>'
        f'<link name="bar"><inertial><origin xyz="0 0 0.1"/><mass value="0.5"/>{inertia}'
        f'</inertial><visual><origin xyz="0 0 0.1"/><geometry>{bar}</geometry></visual>'
        f'<collision><origin xyz="0 0 0.1"/><geometry>{bar}</geometry></collision></link>'
        '<joint name="hinge" type="revolute"><parent link="post"/><child link="bar"/>'
        f'<origin xyz="0 0 {PIVOT - 0.06}"/><axis xyz="1 0 0"/>{limit}</joint></robot>\n'
    )


def _import(tmp_path: Path, limit: str) -> tuple[dict, str]:
    urdf = tmp_path / "bar.urdf"
    urdf.write_text(_urdf(limit))
    done = import_robot(urdf, tmp_path / "out")
    load_spec(done.spec_path)
    spec = yaml.safe_load(done.spec_path.read_text())
    return {j["name"]: j for j in spec["joints"]}["hinge"], "\n".join(done.lines)


def _height_above_slab(angle: float) -> float:
    """Lowest bar corner above the slab top (m) with the hinge at `angle` rad about x."""
    y, z = np.meshgrid([-BAR[0] / 2, BAR[0] / 2], [0.0, BAR[1]])
    height = PIVOT + y * math.sin(angle) + z * math.cos(angle)
    return float(height.min()) - SLAB_TOP


def test_estimated_limits_stop_short_of_the_slab(tmp_path):
    hinge, lines = _import(tmp_path, '<limit effort="5" velocity="2"/>')
    assert "narrowed to" in lines and "hinge" in lines
    contact = [  # the angle (rad) each way where the bar reaches the slab, by hand
        next(a for a in np.arange(0.0, math.pi, 1e-4) * sign if _height_above_slab(a) < 0)
        for sign in (-1.0, 1.0)
    ]
    for limit, touch in zip((hinge["lower"], hinge["upper"]), contact, strict=True):
        assert _height_above_slab(limit) > 0.0  # free at the narrowed limit
        assert 0.0 < abs(touch) - abs(limit) < math.radians(5.0)  # and not much short of it
    assert {"lower", "upper"} <= set(hinge["estimated"])


def test_published_limits_are_kept_even_where_links_meet(tmp_path):
    hinge, lines = _import(tmp_path, '<limit lower="-3.0" upper="3.0" effort="5" velocity="2"/>')
    assert (hinge["lower"], hinge["upper"]) == (-3.0, 3.0)
    assert "narrowed" not in lines
