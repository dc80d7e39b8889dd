"""MJCF import of joints (issue 31): slide -> prismatic, hinge without range -> continuous,
ball -> three revolute joints, a free root -> the floating base, two joints in one body -> a
chain through an added link, a joint `pos` -> the link frame moved to it."""

from __future__ import annotations

import pytest

from mjcf_models import INERTIAL, arm, joints, listed, spec_of, write


def test_slide_is_prismatic_and_a_hinge_without_range_is_continuous(tmp_path):
    text = arm('<joint name="j1" axis="0 1 0"/>', "").replace(
        '<body name="link1" pos="0 0 0.2">',
        '<body name="slider" pos="0 0 0.2"><joint name="s1" type="slide" axis="1 0 0" '
        f'range="-0.2 0.3"/>{INERTIAL}</body><body name="link1" pos="0 0 0.2">',
    )
    spec = spec_of(write(tmp_path, text), tmp_path / "out")
    s1, j1 = joints(spec)["s1"], joints(spec)["j1"]
    assert (s1["type"], s1["axis"], s1["lower"], s1["upper"]) == (
        "prismatic",
        [1.0, 0, 0],
        -0.2,
        0.3,
    )
    assert j1["type"] == "continuous" and j1["axis"] == [0.0, 1.0, 0.0]


def test_a_ball_joint_is_three_revolute_joints(tmp_path):
    spec = spec_of(write(tmp_path, arm('<joint name="b" type="ball"/>')), tmp_path / "out")
    found = joints(spec)
    assert [found[n]["axis"] for n in ("b_x", "b_y", "b")] == [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
    assert "joints.b.type" in listed(spec)


def test_a_free_root_is_the_floating_base(tmp_path):
    text = arm().replace('<body name="base">', '<body name="base" pos="0 0 1"><freejoint/>')
    spec = spec_of(write(tmp_path, text), tmp_path / "out")
    assert spec["floating_base"] is True
    assert spec["joints"][0]["type"] == "floating"


def test_two_joints_in_one_body_are_a_chain_and_a_joint_pos_moves_the_link_frame(tmp_path):
    text = arm(
        '<joint name="a" axis="1 0 0" range="-1 1"/>'
        '<joint name="b" axis="0 1 0" pos="0 0 0.05" range="-1 1"/>'
    )
    spec = spec_of(write(tmp_path, text), tmp_path / "out")
    a, b = joints(spec)["a"], joints(spec)["b"]
    assert a["child"] == b["parent"] == "a_link"
    assert b["xyz"] == pytest.approx([0, 0, 0.05])
    link1 = next(x for x in spec["links"] if x["name"] == "link1")
    assert link1["com"] == pytest.approx([0, 0, 0.05])  # the CoM at 0.1 in the body frame
    assert "links.a_link" in listed(spec)
