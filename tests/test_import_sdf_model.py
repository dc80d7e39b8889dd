"""The SDFormat reader gives the source model itself (importer/formats/sdf/tree.py, issue 39):
`read` sets `source.robot` with its numbers as plain floats (no text round trip), the kept
document the source differences read is that model written as a URDF (and reads back to it),
and a number the frame arithmetic makes that is not finite is refused in one line."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

import model_numbers
from simkit.errors import SpecError
from simkit.importer import formats
from simkit.importer import read as read_shell
from simkit.importer.diagnostics import Policy, Report
from simkit.importer.formats import sdf
from simkit.importer.formats.urdf.model import robot_of
from simkit.importer.read.model import Robot
from simkit.importer.read.options import ReadOptions

FILES = Path(__file__).resolve().parent / "sdf_files"


def _read(path: Path):
    """The SDF reader alone (no `formats.load`, which would read a document it left)."""
    options = ReadOptions()
    return sdf.read(read_shell.shell(path, (), Report(Policy()), options), options)


@pytest.mark.parametrize("name", ["frames.sdf", "universal.sdf", "world.sdf", "scopes.sdf"])
def test_the_reader_gives_the_model_numbers_as_floats(name):
    """The reader's own `Robot`, each number a plain float (line numbers aside)."""
    robot = _read(FILES / name).robot
    assert isinstance(robot, Robot) and robot.joints
    found = model_numbers.numbers(robot)
    assert found and all(type(v) is float for _, v in found), found[:3]


@pytest.mark.parametrize("name", ["frames.sdf", "universal.sdf", "world.sdf"])
def test_the_kept_document_is_the_model_written(name):
    """The kept copy's document (what provenance reads) reads back to the reader's model,
    places included."""
    source = _read(FILES / name)
    assert robot_of(replace(source.kept, closures=[])) == source.robot


OVERFLOW = """<?xml version="1.0"?>
<sdf version="1.9"><model name="far">
  <link name="a"/>
  <link name="b"><pose>1e308 0 0 0 0 0</pose></link>
  <link name="c"><pose relative_to="b">1e308 0 0 0 0 0</pose></link>
  <joint name="j" type="fixed"><parent>a</parent><child>b</child></joint>
  <joint name="k" type="fixed"><parent>b</parent><child>c</child></joint>
</model></sdf>
"""


def test_a_pose_that_is_not_finite_is_refused_in_one_line(tmp_path):
    """Finite poses whose sum overflows: one line naming the file, line and origin."""
    path = tmp_path / "far.sdf"
    path.write_text(OVERFLOW)
    with pytest.warns(RuntimeWarning), pytest.raises(SpecError) as caught:
        formats.load(path, report=Report(Policy()))  # the model's numbers: read/model.infinite
    text = str(caught.value)
    assert "far.sdf:" in text and "origin" in text and "finite" in text and "\n" not in text
