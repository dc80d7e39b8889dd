"""MJCF import of sites, actuators and what a kit cannot carry (issue 31): sites -> frames,
a joint actuator's bound -> the joint's effort, tendons, cameras, sensors and the actuators'
gains listed in `source_differences` with their reason."""

from __future__ import annotations

import pytest

from mjcf_models import arm, joints, listed, spec_of, write

EXTRA = """
  <tendon><fixed name="couple"><joint joint="j1" coef="1"/></fixed></tendon>
  <actuator><motor name="m1" joint="j1" gear="50" ctrlrange="-2 2"/></actuator>
  <sensor><jointpos name="q1" joint="j1"/></sensor>
"""


@pytest.fixture(scope="module")
def spec(tmp_path_factory):
    folder = tmp_path_factory.mktemp("parts")
    text = arm(
        '<joint name="j1" axis="0 1 0" range="-1 1"/><site name="tool" pos="0 0 0.2"/>'
        '<camera name="eye" pos="0 0 0.1"/>',
        EXTRA,
    )
    return spec_of(write(folder, text), folder / "out")


def test_a_site_is_a_frame(spec):
    frames = {f["name"]: f for f in spec["frames"]}
    assert frames["tool"]["parent"] == "link1"
    assert frames["tool"]["xyz"] == pytest.approx([0, 0, 0.2])


def test_a_motor_bound_is_the_joint_effort(spec):
    assert joints(spec)["j1"]["effort_peak"] == pytest.approx(100.0)  # gear 50 x ctrl 2


def test_what_a_kit_cannot_carry_is_listed(spec):
    found = listed(spec)
    assert "tendon" in found["tendons.couple"]
    assert "camera" in found["cameras.eye"]
    assert found["sensors.q1"] and found["actuators.m1.gains"]
