"""An SDFormat link with two parent joints closes the same way a URDF's does (issue 42 class 8,
"one rule for both"): the tree from the first joint, the later joint a weld in the spec's
`loops` at the pose the tree gives at home, listed in `source_differences`."""

from __future__ import annotations

import pytest
import yaml

from simkit.importer import import_robot

LOOPED = """<?xml version="1.0"?>
<sdf version="1.9"><model name="looped">
  <link name="base"><inertial><mass>2</mass></inertial></link>
  <link name="upper"><pose relative_to="shoulder">0 0 0.2 0 0 0</pose>
    <inertial><mass>1</mass></inertial></link>
  <link name="tip"><pose relative_to="upper">0 0 0.2 0 0 0</pose>
    <inertial><mass>0.2</mass></inertial></link>
  <joint name="shoulder" type="revolute"><parent>base</parent><child>upper</child>
    <pose relative_to="base">0 0 0 0 0 0</pose>
    <axis><xyz>0 0 1</xyz><limit><lower>-1</lower><upper>1</upper><effort>50</effort>
    <velocity>2</velocity></limit></axis></joint>
  <joint name="tip_mount" type="fixed"><parent>upper</parent><child>tip</child></joint>
  <joint name="tip_to_base" type="fixed"><parent>base</parent><child>tip</child></joint>
</model></sdf>
"""


def test_sdf_second_parent_becomes_a_weld(tmp_path):
    path = tmp_path / "looped.sdf"
    path.write_text(LOOPED)
    done = import_robot(path, tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert "tip_to_base" not in {j["name"] for j in spec["joints"]}
    (loop,) = spec["loops"]
    assert (loop["type"], loop["link1"], loop["link2"]) == ("weld", "base", "tip")
    assert loop["xyz"] == pytest.approx([0, 0, 0.4], abs=1e-9)
    listed = {d["what"]: d["reason"] for d in spec["source_differences"]}
    assert "closed loop" in listed["joints.tip_to_base"]
