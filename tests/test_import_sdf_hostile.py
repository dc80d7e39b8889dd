"""Hostile SDFormat input (importer/formats/sdf/files.py): an `<include>` or mesh `<uri>` that
leaves the model's folder (`../`, an absolute path, `file:///etc/...`, a symbolic link out)
or names the network is refused in one line, and no file outside is read."""

from __future__ import annotations

from pathlib import Path

import pytest

from simkit.errors import SpecError
from simkit.importer import formats
from simkit.importer.diagnostics import Policy, Report

ROBOT = """<?xml version="1.0"?>
<sdf version="1.9">
  <model name="robot">
    <link name="a"/>
    {}
  </model>
</sdf>
"""


def _model(tmp_path: Path, element: str) -> Path:
    """A Gazebo model folder `models/robot` holding `element`, a secret beside it."""
    folder = tmp_path / "models" / "robot"
    folder.mkdir(parents=True)
    (folder / "model.config").write_text(
        '<model><name>robot</name><sdf version="1.9">model.sdf</sdf></model>'
    )
    (folder / "model.sdf").write_text(ROBOT.format(element))
    (tmp_path / "secret.sdf").write_text(ROBOT.format(""))
    return folder


def _refused(folder: Path) -> str:
    with pytest.raises(SpecError) as caught:
        formats.load(formats.pick(folder).path, report=Report(Policy()))
    text = str(caught.value)
    assert "\n" not in text and "model.sdf" in text
    return text


INCLUDE = "<include><uri>{}</uri></include>"
MESH = (
    '<link name="b"><visual name="v"><geometry><mesh><uri>{}</uri></mesh></geometry></visual>'
    "</link>"
)


@pytest.mark.parametrize("shape", [INCLUDE, MESH])
@pytest.mark.parametrize("uri", ["../../secret.sdf", "ABS", "file://ABS", "file:///etc/passwd"])
def test_a_uri_out_of_the_model_folder_is_refused(tmp_path, shape, uri):
    uri = uri.replace("ABS", str(tmp_path / "secret.sdf"))
    assert "outside the model's folder" in _refused(_model(tmp_path, shape.format(uri)))


def test_a_symlink_out_is_refused(tmp_path):
    folder = _model(tmp_path, INCLUDE.format("inner.sdf"))
    (folder / "inner.sdf").symlink_to(tmp_path / "secret.sdf")
    assert "outside the model's folder" in _refused(folder)


@pytest.mark.parametrize("uri", ["http://example.com/m.sdf", "https://example.com/m.stl"])
def test_a_network_uri_is_never_fetched(tmp_path, uri):
    assert "never fetched" in _refused(_model(tmp_path, INCLUDE.format(uri)))


def test_model_uri_names_only_a_sibling_model(tmp_path):
    """model://NAME is the model folder or a sibling holding model.config; `..` is refused."""
    assert "no such model" in _refused(_model(tmp_path, INCLUDE.format("model://../x")))
