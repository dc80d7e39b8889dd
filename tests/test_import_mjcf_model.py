"""The MJCF reader builds the source model (read/model.py) itself, from MuJoCo's compiled
arrays, numbers as plain floats with no text between (issue 39): its body welds are model
closure joints, and the copy the source differences read is the model written as a URDF
document, which reads back to the same model."""

from __future__ import annotations

import shutil
from dataclasses import replace

import pytest

import model_numbers
from mjcf_models import arm, write
from simkit.importer import read
from simkit.importer.diagnostics import Policy, Report
from simkit.importer.formats import mjcf
from simkit.importer.formats.urdf.model import robot_of
from simkit.importer.read.model import At, Joint
from simkit.importer.read.options import ReadOptions

WELDED = """<mujoco model="welded">
  <worldbody>
    <body name="base"><inertial pos="0 0 0" mass="2" diaginertia="1e-2 1e-2 1e-2"/>
      <geom type="box" size="0.05 0.05 0.02" rgba="1 0 0 1" contype="0" conaffinity="0"/>
      <body name="a" pos="0 0 0.02"><joint name="ja" axis="0 1 0" range="-1 1"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.2" size="0.02"/></body>
      <body name="b" pos="0.1 0 0.02"><joint name="jb" axis="0 1 0"/>
        <geom type="sphere" size="0.02"/><site name="tip" pos="0 0 0.1"/></body>
    </body>
  </worldbody>
  <equality><weld name="tie" body1="a" body2="b"/></equality>
</mujoco>
"""


@pytest.fixture
def reading(tmp_path):
    """Read an MJCF with the format's own `read` (not `formats.load`, which would fill a
    missing model from a document); the scratch meshes removed after."""
    made = []

    def run(text: str):
        path = write(tmp_path, text)
        options = ReadOptions()
        source = mjcf.read(read.shell(path, (), Report(Policy()), options), options)
        made.extend(source.scratch)
        return source

    yield run
    for folder in made:
        shutil.rmtree(folder, ignore_errors=True)


def test_the_reader_builds_the_model_with_plain_floats(reading):
    source = reading(arm())
    robot = source.robot
    assert robot is not None and robot.name == "arm"
    numbers = model_numbers.numbers(robot)
    assert numbers and [(w, v) for w, v in numbers if type(v) is not float] == []
    joint = robot.joint("j1")
    assert (joint.type, joint.parent, joint.child) == ("revolute", "base", "link1")
    assert joint.origin.xyz == (0.0, 0.0, 0.2) and joint.axis == (0.0, 1.0, 0.0)
    assert (joint.limit.lower, joint.limit.upper) == (-1.0, 1.0)
    assert robot.link("link1").inertial.mass == 1.0
    assert joint.at == At("joint", "j1", 5)  # the MJCF line of the joint (its body's)


def test_a_body_weld_is_a_closure_joint_of_the_model(reading):
    source = reading(WELDED)
    tie = Joint("tie", "fixed", At("joint", "tie"), "a", "b", listed="equality.tie")
    assert source.closures == [tie]
    assert source.robot.joint("jb").type == "continuous"
    assert source.robot.link("tip") is not None  # a site: a frame link


def test_the_kept_document_reads_back_to_the_model(reading):
    source = reading(WELDED)
    kept = source.kept.root
    assert [e.get("name") for e in kept.findall("joint")] == [j.name for j in source.robot.joints]
    assert robot_of(replace(source.kept, closures=[])) == source.robot
