"""MJCF import refusals (issue 31): one line naming the file, never a traceback, nothing
written: several robots, no joint, a file outside the model's folder, malformed XML, a model
MuJoCo cannot compile."""

from __future__ import annotations

import pytest

from mjcf_models import INERTIAL, arm, write
from simkit.errors import SpecError
from simkit.importer import import_robot


def _refused(path, out) -> str:
    with pytest.raises(SpecError) as err:
        import_robot(path, out)
    text = str(err.value)
    assert "\n" not in text and path.name in text
    assert not (out / "model.yaml").exists()
    return text


def test_several_robots_are_refused(tmp_path):
    two = arm().replace(
        "</worldbody>",
        f'<body name="other"><joint name="k" axis="1 0 0"/>{INERTIAL}</body></worldbody>',
    )
    assert "several robots" in _refused(write(tmp_path, two), tmp_path / "out")


def test_a_model_without_joints_is_refused(tmp_path):
    text = arm("")
    assert "no joint" in _refused(write(tmp_path, text), tmp_path / "out")


def test_an_include_outside_the_folder_is_refused_before_mujoco_reads_it(tmp_path):
    write(tmp_path, "<mujoco/>", "secret.xml")
    text = arm(extra="").replace("<worldbody>", '<include file="../secret.xml"/><worldbody>')
    line = _refused(write(tmp_path / "model", text), tmp_path / "out")
    assert "outside the model's folder" in line and "include" in line


def test_a_mesh_outside_the_folder_is_refused(tmp_path):
    text = arm(extra='<asset><mesh name="m" file="/etc/hostname"/></asset>')
    assert "outside the model's folder" in _refused(write(tmp_path, text), tmp_path / "out")


def test_malformed_xml_and_an_uncompilable_model_are_one_line(tmp_path):
    assert "malformed XML" in _refused(write(tmp_path, "<mujoco><worldbody>"), tmp_path / "o")
    bad = arm('<joint name="j1" type="nonsense"/>')
    assert "MuJoCo cannot compile" in _refused(write(tmp_path, bad), tmp_path / "o")
