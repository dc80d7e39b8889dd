"""The source model (importer/read/model.py): every format's reader gives the translation one
typed model, numbers as numbers; the translation reads nothing else of the source (issue 39)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from simkit.errors import SpecError
from simkit.importer import formats, translate
from simkit.importer.diagnostics import Policy, Report
from simkit.importer.draft import DENSITY, Draft, Options
from simkit.importer.formats.urdf.document import document
from simkit.importer.formats.urdf.model import robot_of
from simkit.importer.read.model import At, Robot

URDF = """<?xml version="1.0"?>
<robot name="two">
  <material name="red"><color rgba="1 0 0 1"/></material>
  <link name="base">
    <inertial><origin xyz="0 0 0.05"/><mass value="2"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry><material name="red"/></visual>
    <collision><geometry><cylinder radius="0.1" length="0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0 0 0.2" rpy="0 0 0"/><mass value="0.5"/>
      <inertia ixx="0.002" iyy="0.002" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><origin xyz="0,0,0.2"/><geometry><capsule radius="0.02" length="0.3"/></geometry>
    </visual>
  </link>
  <link name="finger"/>
  <joint name="shoulder" type="revolute">
    <origin xyz="0 0 0.1" rpy="0 0 1.5708 0"/><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit lower="-1.5" upper="1.5" effort="10" velocity="2"/>
    <dynamics damping="0.1"/><calibration rising="0"/>
  </joint>
  <joint name="grip" type="prismatic">
    <origin xyz="0 0 0.4"/><parent link="arm"/><child link="finger"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.04" effort="5" velocity="0.1"/>
    <mimic joint="shoulder" multiplier="0.01" offset="0.02"/>
  </joint>
</robot>
"""


def _read(tmp_path: Path, text: str = URDF, strict: bool = False):
    path = tmp_path / "two.urdf"
    path.write_text(text)
    report = Report(Policy(strict=strict))
    return formats.load(path, report=report), report


def test_numbers_are_numbers_and_places_are_kept(tmp_path):
    """Each number is a float (or a tuple of them) where it is read; each node keeps its
    element's tag, name and line."""
    source, _ = _read(tmp_path)
    robot = source.robot
    assert isinstance(robot, Robot) and robot.name == "two"
    base, arm, finger = robot.links
    assert base.inertial.mass == 2.0 and base.inertial.origin.xyz == (0.0, 0.0, 0.05)
    assert base.inertial.inertia == (0.01, 0.01, 0.01, 0.0, 0.0, 0.0)
    assert base.visuals[0].shape.size == (0.2, 0.2, 0.1)
    assert base.visuals[0].material.name == "red" and base.visuals[0].material.rgba is None
    assert base.collisions[0].shape.radius == 0.1 and base.collisions[0].shape.length == 0.1
    assert robot.materials[0].rgba == (1.0, 0.0, 0.0, 1.0)
    assert finger.inertial is None and not finger.drawn
    shoulder, grip = robot.joints
    assert shoulder.limit.lower == -1.5 and shoulder.limit.effort == 10.0
    assert shoulder.dynamics.damping == 0.1 and shoulder.dynamics.friction is None
    assert shoulder.unknown == (At("calibration", None, 20),)
    assert grip.mimic.joint == "shoulder" and (grip.mimic.multiplier, grip.mimic.offset) == (
        0.01,
        0.02,
    )
    assert shoulder.at == At("joint", "shoulder", 17)
    assert arm.at.sourceline == 10


def test_lenient_numbers_are_read_once_and_reported_once(tmp_path):
    """A comma list and a four-number rpy are read where the model is read, one report
    line each; --strict refuses the first, naming its line."""
    source, report = _read(tmp_path)
    assert source.robot.links[1].visuals[0].origin.xyz == (0.0, 0.0, 0.2)
    assert source.robot.joints[0].origin.rpy == (0.0, 0.0, 1.5708)
    lenient = [line for line in report.lines if "strtod" in line or "more than 3" in line]
    assert len(lenient) == 2
    assert lenient[0].startswith("two.urdf:13: origin: changed: 'xyz' is '0,0,0.2'")
    assert lenient[1].startswith("two.urdf:18: origin: changed: 'rpy' has more than 3")
    with pytest.raises(SpecError) as refused:  # the first in document order
        _read(tmp_path, strict=True)
    assert refused.value.line == 13


def test_document_reads_back_to_the_same_model(tmp_path):
    """The model written as URDF (formats/urdf/document.py) reads back to an equal model."""
    source, _ = _read(tmp_path)
    again = robot_of(replace(source, root=document(source.robot), closures=[]))
    assert again == source.robot


def test_translation_reads_only_the_model(tmp_path):
    """With the document gone, the translation still makes the spec from the model."""
    source, report = _read(tmp_path)
    without = replace(source, root=None)
    draft = Draft(without, without.path, tmp_path, report, Options("two", None, False, DENSITY))
    translate.to_spec(draft)
    joints = {j["name"]: j for j in draft.spec["joints"]}
    assert joints["shoulder"]["lower"] == -1.5 and joints["shoulder"]["damping"] == 0.1
    assert joints["grip"]["mimic"] == {"joint": "shoulder", "multiplier": 0.01, "offset": 0.02}
    assert [link["name"] for link in draft.spec["links"]] == ["base", "arm", "finger"]


def test_document_keeps_a_name_that_reads_none(tmp_path):
    """A link or joint named "None" keeps its name in the written document (only a value
    the model does not hold is left out)."""
    text = URDF.replace('name="finger"', 'name="None"').replace('link="finger"', 'link="None"')
    source, _ = _read(tmp_path, text)
    written = document(source.robot)
    assert [link.get("name") for link in written.findall("link")][-1] == "None"
    assert robot_of(replace(source, root=written, closures=[])) == source.robot
