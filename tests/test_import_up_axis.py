"""COLLADA `<up_axis>Y_UP</up_axis>` meshes (issue 15, found on a humanoid): kept as stored,
as ROS tools load them, unless the URDF's own child joints and inertial CoMs say the meshes
were drawn Y-up; then turned Z-up and reported. Tiny URDFs and a DAE written by the test."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from simkit.importer import import_robot
from simkit.importer.formats import load
from simkit.importer.translate.up_axis import is_y_up, turn_y_up


def _shank_dae(folder: Path) -> Path:
    """A 0.2 m bar along the file's +Y, marked Y_UP: drawn Y-up it stands along +Z."""
    import trimesh

    bar = trimesh.creation.box(extents=(0.02, 0.2, 0.02))
    bar.apply_translation((0.0, 0.1, 0.0))
    text = trimesh.exchange.dae.export_collada(bar)
    text = text.decode() if isinstance(text, bytes) else text
    path = folder / "shank.dae"
    path.write_text(text.replace("Z_UP", "Y_UP"), encoding="utf-8")
    return path


def _urdf(folder: Path, tip: str) -> Path:
    """Base, then a shank link whose child joint and CoM lie at `tip` and half of it."""
    half = " ".join(str(float(v) / 2) for v in tip.split())
    inertia = '<inertia ixx="1e-3" iyy="1e-3" izz="1e-3" ixy="0" ixz="0" iyz="0"/>'
    link = (
        '<link name="{n}"><inertial><origin xyz="{c}"/><mass value="1"/>' + inertia + "</inertial>"
        '<visual><geometry><mesh filename="shank.dae"/></geometry></visual></link>'
    )
    text = (
        '<robot name="leg">'
        + link.format(n="base", c="0 0 0")
        + link.format(n="shank", c=half)
        + link.format(n="foot", c="0 0 0")
        + '<joint name="knee" type="revolute"><parent link="base"/><child link="shank"/>'
        '<axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="5" velocity="2"/></joint>'
        '<joint name="ankle" type="revolute"><parent link="shank"/><child link="foot"/>'
        f'<origin xyz="{tip}"/><axis xyz="1 0 0"/>'
        '<limit lower="-1" upper="1" effort="5" velocity="2"/></joint></robot>'
    )
    path = folder / "leg.urdf"
    path.write_text(text, encoding="utf-8")
    return path


def test_y_up_is_read_from_the_asset(tmp_path):
    dae = _shank_dae(tmp_path)
    assert is_y_up(dae)
    dae.write_text(dae.read_text().replace("Y_UP", "Z_UP"))
    assert not is_y_up(dae)


@pytest.mark.parametrize(("tip", "turned"), [("0 0 0.2", True), ("0 0.2 0", False)])
def test_meshes_turn_only_where_the_joints_and_inertials_say(tmp_path, tip, turned):
    _shank_dae(tmp_path)
    urdf = _urdf(tmp_path, tip)
    turn, why = turn_y_up(load(urdf))
    assert turn is turned
    assert ("turned Z-up" in why) is turned
    done = import_robot(urdf, tmp_path / "out")
    import trimesh

    written = trimesh.load(next((tmp_path / "out" / "meshes").glob("shank*.stl")))
    along = int(np.argmax(written.bounds[1] - written.bounds[0]))
    assert along == (2 if turned else 1)  # the bar ends at the ankle joint
    assert any("Y_UP" in line for line in done.lines) is turned


def test_stance_scores_compare_in_order():
    """The stance search's last pass ranks poses by separable contact first, then by all
    contact (pairs its 200 samples call always touching that the kit's 10000 may not)."""
    from simkit.importer.fixups.stance import better

    assert better((-0.0, -0.001), (-0.0, -0.003))
    assert not better((-0.002, 0.0), (-0.0, -0.003))
    assert better(-0.001, -0.002) and not better(-0.002, -0.002)
