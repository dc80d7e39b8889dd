"""The source comparison reads a kept URDF as PyBullet and the importer do (issue 22): numbers
as C's strtod reads them, geometry it does not compare left out (yourdfpy refuses PyBullet's
`<capsule>`), and a massless link's CoM and inertia listed as meaningless."""

from __future__ import annotations

import numpy as np
import yaml

from simkit.check.source.urdf import load_urdf
from simkit.importer import import_robot

URDF = """<?xml version="1.0"?>
<robot name="r">
  <link name="world"><inertial><mass value="0"/>
    <inertia ixx="0.2" iyy="0.2" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><capsule radius="0.05" length="0.3"/></geometry></visual>
    <visual><geometry><box size="0.1 0.1 0.3"/></geometry></visual>
  </link>
  <joint name="j" type="revolute"><parent link="world"/><child link="arm"/>
    <origin xyz="0.07, 0, 0.5" rpy="-1.57. 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>
</robot>
"""


def test_numbers_are_read_as_strtod_and_unknown_shapes_left_out(tmp_path):
    path = tmp_path / "r.urdf"
    path.write_text(URDF)
    robot = load_urdf(path)
    (joint,) = robot.joints
    origin = np.asarray(joint.origin)
    assert np.allclose(origin[:3, 3], [0.07, 0, 0.5])
    assert np.isclose(np.arctan2(origin[2, 1], origin[2, 2]), -1.57)


def test_a_massless_links_com_and_inertia_are_listed(tmp_path):
    path = tmp_path / "r.urdf"
    path.write_text(URDF)
    done = import_robot(path, tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    listed = {item["what"]: item["reason"] for item in spec["source_differences"]}
    assert "no CoM or inertia" in listed["links.world.inertia"]
    assert "links.world.com" in listed


def test_a_transmission_naming_a_joint_is_no_reshaped_joint(tmp_path):
    """`<transmission><joint name=...>` (no type) is a block's reference to a joint, not a
    robot joint of a type the kit lacks."""
    path = tmp_path / "r.urdf"
    block = (
        '<transmission name="t"><type>transmission_interface/SimpleTransmission</type>'
        '<joint name="j"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>'
        "</transmission>\n</robot>"
    )
    path.write_text(URDF.replace("</robot>", block))
    done = import_robot(path, tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert not [d for d in spec["source_differences"] if d["what"].startswith("joints.j.")]
