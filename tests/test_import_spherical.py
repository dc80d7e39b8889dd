"""URDF `spherical` joints (PyBullet's ball joint) imported as three revolute joints about the
joint frame's x, y, z axes through massless links (importer/translate/ball_joints.py, issue 22)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from simkit.errors import SpecError
from simkit.importer import import_robot
from simkit.spec.validate import load_spec

LIMITED = '<limit effort="20" lower="0.5" upper="0.7" twist="0.9" velocity="2"/>'
#: the ball's pose in the base frame (m, rad)
ORIGIN = ("0.05 0 0.1", "0.1 0 0.3")


def _urdf(tmp_path: Path, limit: str = "", extra: str = "") -> Path:
    """Two boxes joined by a spherical joint (`limit`: its `<limit>` element, if any)."""
    inertia = 'ixx="0.01" iyy="0.01" izz="0.005" ixy="0" ixz="0" iyz="0"'
    box = '<geometry><box size="0.06 0.06 0.3"/></geometry>'
    text = f"""<?xml version="1.0"?>
<robot name="ball">
  <link name="base">
    <inertial><mass value="2"/><inertia {inertia}/></inertial>
    <visual><geometry><box size="0.3 0.3 0.1"/></geometry></visual>
    <collision><geometry><box size="0.3 0.3 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0 0 0.25"/><mass value="0.5"/><inertia {inertia}/></inertial>
    <visual><origin xyz="0 0 0.25"/>{box}</visual>
    <collision><origin xyz="0 0 0.25"/>{box}</collision>
  </link>
  <joint name="shoulder" type="spherical">
    <parent link="base"/>
    <child link="arm"/>
    <origin xyz="{ORIGIN[0]}" rpy="{ORIGIN[1]}"/>
    <axis xyz="0 0 1"/>
    {limit}
  </joint>{extra}
</robot>
"""
    path = tmp_path / "ball.urdf"
    path.write_text(text, encoding="utf-8")
    return path


def _joints(done) -> dict:
    spec, _ = load_spec(done.spec_path)
    return {j.name: j for j in spec.joints}, {link.name: link for link in spec.links}


def test_limited_ball_is_three_revolute_joints(tmp_path):
    done = import_robot(_urdf(tmp_path, LIMITED), tmp_path / "out")
    joints, links = _joints(done)
    chain = [joints[n] for n in ("shoulder_x", "shoulder_y", "shoulder")]
    assert [(j.parent, j.child) for j in chain] == [
        ("base", "shoulder_x_link"),
        ("shoulder_x_link", "shoulder_y_link"),
        ("shoulder_y_link", "arm"),
    ]
    assert [j.axis for j in chain] == [(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)]
    assert [j.limits() for j in chain] == [(-0.5, 0.5), (-0.7, 0.7), (-0.9, 0.9)]
    assert {j.type for j in chain} == {"revolute"} and {j.effort_peak for j in chain} == {20.0}
    assert chain[0].xyz == (0.05, 0.0, 0.1) and chain[0].rpy == (0.1, 0.0, 0.3)
    assert chain[1].xyz == chain[2].xyz == (0.0, 0.0, 0.0) and chain[1].rpy is None
    for name in ("shoulder_x_link", "shoulder_y_link"):
        link = links[name]
        assert link.mass <= 0.001 and not link.solid and "mass" in link.estimated
    said = [line for line in done.lines if "spherical joint shoulder:" in line]
    assert len(said) == 1 and said[0].startswith("ball.urdf:13: joint[shoulder]: changed:")
    assert "three revolute joints shoulder_x, shoulder_y, shoulder" in said[0]
    assert "+-0.5, +-0.7, +-0.9 rad" in said[0]


@pytest.mark.parametrize(
    "limit",
    [
        "",  # no <limit>
        '<limit effort="20" lower="0.5" upper="0.7" velocity="2"/>',  # no twist
        '<limit lower="0.5" upper="0.7" twist="0.9"/>',  # no effort: PyBullet applies none
    ],
)
def test_ball_without_a_full_limit_turns_freely(tmp_path, limit):
    done = import_robot(_urdf(tmp_path, limit), tmp_path / "out")
    joints, _ = _joints(done)
    chain = [joints[n] for n in ("shoulder_x", "shoulder_y", "shoulder")]
    assert {j.type for j in chain} == {"continuous"}
    assert all(j.limits() == (None, None) for j in chain)
    assert any("shoulder_y_link; continuous (no <limit>" in line for line in done.lines)


def test_derived_names_avoid_the_urdfs_own(tmp_path):
    taken = (
        '<link name="shoulder_x_link"><inertial><mass value="0.1"/>'
        '<inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        '<joint name="shoulder_x" type="fixed">'
        '<parent link="arm"/><child link="shoulder_x_link"/><origin xyz="0 0 0.4"/></joint>'
    )
    done = import_robot(_urdf(tmp_path, extra=taken), tmp_path / "out")
    joints, _ = _joints(done)
    assert joints["shoulder_x2"].child == "shoulder_x2_link"
    assert joints["shoulder_x"].type == "fixed"  # the URDF's joint keeps its name


def test_strict_refuses_a_ball_in_one_line(tmp_path):
    with pytest.raises(SpecError) as err:
        import_robot(_urdf(tmp_path, LIMITED), tmp_path / "out", strict=True)
    text = str(err.value)
    assert "\n" not in text and text.startswith(f"{tmp_path / 'ball.urdf'}:13: joint[shoulder]:")
    assert "spherical joint shoulder" in text and "--strict refuses it" in text
    assert not list((tmp_path / "out").glob("*.yaml"))  # nothing half-written


def test_ball_naming_a_missing_link_is_one_line(tmp_path):
    path = _urdf(tmp_path, LIMITED)
    path.write_text(path.read_text().replace('<child link="arm"/>', '<child link="nope"/>'))
    with pytest.raises(SpecError, match=r"ball.urdf:13: joint\[shoulder\]: unknown child link"):
        import_robot(path, tmp_path / "out")


def _pybullet_link_frame(urdf: Path, quat_xyzw) -> tuple[np.ndarray, np.ndarray]:
    """World position and rotation matrix of `arm`'s URDF frame in PyBullet with the ball
    joint at `quat_xyzw` (PyBullet reads the spherical joint itself: the reference)."""
    import pybullet

    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(str(urdf), useFixedBase=True, physicsClientId=client)
        pybullet.resetJointStateMultiDof(body, 0, list(quat_xyzw), physicsClientId=client)
        state = pybullet.getLinkState(
            body, 0, computeForwardKinematics=True, physicsClientId=client
        )
        rot = pybullet.getMatrixFromQuaternion(state[5], physicsClientId=client)
        return np.array(state[4]), np.array(rot).reshape(3, 3)
    finally:
        pybullet.disconnect(client)


@pytest.mark.slow
def test_kit_builds_and_its_chain_turns_as_the_ball(tmp_path, kit_factory):
    """The imported kit passes every check, and MuJoCo's FK of the three joints at the ball
    rotation's intrinsic x-y-z angles puts the child link where PyBullet puts it."""
    import mujoco
    from scipy.spatial.transform import Rotation

    urdf = _urdf(tmp_path, LIMITED)
    result = kit_factory(str(import_robot(urdf, tmp_path / "out").spec_path))
    assert result.findings and all(f.ok for f in result.findings)
    model = mujoco.MjModel.from_xml_path(str(result.kit_dir / "mjcf" / "ball.xml"))
    data = mujoco.MjData(model)
    names = ("shoulder_x", "shoulder_y", "shoulder")
    address = [model.jnt_qposadr[model.joint(n).id] for n in names]
    arm = model.body("arm").id
    for angles in ((0.3, -0.4, 0.8), (-0.45, 0.6, -0.2), (0.0, 0.0, 0.85), (0.2, 0.65, 0.0)):
        quat = Rotation.from_euler("XYZ", angles).as_quat()  # intrinsic x, then y, then z
        data.qpos[:] = 0.0
        data.qpos[address] = Rotation.from_quat(quat).as_euler("XYZ")
        mujoco.mj_kinematics(model, data)
        xyz, rot = _pybullet_link_frame(urdf, quat)
        assert np.allclose(data.xpos[arm], xyz, atol=1e-6), angles
        assert np.allclose(data.xmat[arm].reshape(3, 3), rot, atol=1e-6), angles


def test_estimated_effort_holds_a_long_childless_link(tmp_path):
    """The effort estimate (twice the static load) counts the carried link's own CoM offset
    as a lever arm: a neck whose CoM is 0.25 m out and has no child joint needs
    2 x 0.5 kg x g x 0.25 m, not the 0.1 m floor of the joint-offset chain (humanoid.urdf's
    neck could not hold its home)."""
    done = import_robot(_urdf(tmp_path), tmp_path / "out")  # no <limit>: effort estimated
    joints, _ = _joints(done)
    needed = 0.99 * 2 * 0.5 * 9.81 * 0.25  # the estimate keeps 3 significant digits
    assert all(joints[n].effort_peak >= needed for n in ("shoulder_x", "shoulder_y", "shoulder"))
