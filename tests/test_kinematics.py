"""Property tests for the kinematics and the number formatter."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mjcompat import full_mass_matrix
from simkit.kitio.fmt import num
from simkit.model.dynamics import axis_inertia
from simkit.model.kinematics import axis_angle, forward, matrix_rpy, quat_wxyz, rpy_matrix
from simkit.pipeline import model_from_spec

angles = st.floats(min_value=-3.1, max_value=3.1, allow_nan=False)
ROSIE = model_from_spec("rosie_1000")


@settings(max_examples=200, deadline=None)
@given(r=angles, p=st.floats(min_value=-1.5, max_value=1.5), y=angles)
def test_rpy_round_trip(r, p, y):
    rot = rpy_matrix((r, p, y))
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(rpy_matrix(matrix_rpy(rot)), rot, atol=1e-9)


@settings(max_examples=200, deadline=None)
@given(x=angles, y=angles, z=angles, q=angles)
def test_axis_angle_and_quaternion(x, y, z, q):
    axis = np.array([x, y, z])
    if np.linalg.norm(axis) < 1e-3:
        return
    axis /= np.linalg.norm(axis)
    rot = axis_angle(axis, q)
    np.testing.assert_allclose(rot @ axis, axis, atol=1e-12)
    assert abs(np.linalg.det(rot) - 1) < 1e-12
    w, *_v = quat_wxyz(rot)
    assert abs(w - abs(np.cos(q / 2))) < 1e-9


@settings(max_examples=50, deadline=None)
@given(q=st.lists(angles, min_size=6, max_size=6))
def test_fk_matches_mujoco_mass_matrix_diagonal(q):
    """axis_inertia (composite inertia about each joint axis) is MuJoCo's mass-matrix diagonal
    minus armature, on the same model."""
    import mujoco

    from simkit.emit import mjcf

    xml = mjcf.emit(ROSIE)["mjcf/rosie_1000.xml"].decode()
    xml = xml.replace(
        '<compiler angle="radian" meshdir="../meshes" autolimits="true" />',
        '<compiler angle="radian" autolimits="true" />',
    )
    import re

    xml = re.sub(r"<mesh [^>]*/>", "", xml)
    xml = re.sub(r'<geom name="[^"]*" class="(visual|collision)"[^>]*/>', "", xml)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    data.qpos[:] = q
    mujoco.mj_forward(model, data)
    full = full_mass_matrix(model, data)
    for i, joint in enumerate(ROSIE.movable_joints):
        expected = full[i, i] - joint.armature
        assert abs(axis_inertia(ROSIE, joint.name, q) - expected) < 1e-9 * max(1, expected)
    poses = forward(ROSIE, q)
    base = poses["base_link"]
    np.testing.assert_allclose(
        (np.linalg.inv(base) @ poses["tool0"])[:3, 3],
        (data.site("tool0").xpos - data.body("base_link").xpos),
        atol=1e-12,
    )


@given(st.floats(allow_nan=False, allow_infinity=False, min_value=-1e9, max_value=1e9))
def test_num_is_stable(x):
    text = num(x)
    assert text != "-0"
    assert abs(float(text) - x) <= max(1e-12, abs(x) * 1e-9)
    assert num(float(text)) == text
