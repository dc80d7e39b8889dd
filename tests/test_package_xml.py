"""package.xml's maintainer and licence come from the spec (`maintainer:`, `license:`); without
them a plain default and one warning line from `simkit build`."""

from __future__ import annotations

from pathlib import Path

import pytest
from catkin_pkg.package import parse_package_string
from click.testing import CliRunner

from simkit.cli import main
from simkit.emit import ros2
from simkit.errors import SpecError
from simkit.kitio import layout
from simkit.pipeline import model_from_spec
from simkit.spec.validate import load_spec

SPEC = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
GIVEN = "maintainer: {name: Jane Doe, email: jane.doe@example.org}\nlicense: Apache-2.0\n"


def _spec(tmp_path: Path, extra: str) -> Path:
    """planar_2r with `extra` top-level lines."""
    path = tmp_path / "planar_2r.yaml"
    path.write_text(SPEC.read_text() + extra)
    return path


def _package(spec: Path):
    robot = model_from_spec(str(spec))
    package = parse_package_string(ros2.emit(robot)[layout.PACKAGE_XML].decode())
    package.validate()  # catkin_pkg: rosdep and bloom's own reader
    return robot, package


def test_maintainer_and_license_come_from_the_spec(tmp_path):
    robot, package = _package(_spec(tmp_path, GIVEN))
    assert [(m.name, m.email) for m in package.maintainers] == [
        ("Jane Doe", "jane.doe@example.org")
    ]
    assert package.licenses == ["Apache-2.0"]
    assert ros2.package_warning(robot) is None


def test_defaults_are_plain_and_warned_about(tmp_path):
    robot, package = _package(SPEC)
    assert [(m.name, m.email) for m in package.maintainers] == [ros2.DEFAULT_MAINTAINER]
    assert "example.com" not in ros2.emit(robot)[layout.PACKAGE_XML].decode()
    assert package.licenses == ["LicenseRef-planar_2r_description"]
    warning = ros2.package_warning(robot)
    assert warning is not None and "\n" not in warning
    assert "no maintainer or license" in warning and "planar_2r.yaml" in warning
    only_license = _spec(tmp_path, GIVEN.splitlines()[0] + "\n")
    assert "no license:" in ros2.package_warning(model_from_spec(str(only_license)))


@pytest.mark.slow
def test_build_prints_one_warning_line(tmp_path):
    result = CliRunner().invoke(
        main, ["build", str(SPEC), "--out", str(tmp_path), "--no-check", "--no-step"]
    )
    assert result.exit_code == 0, result.output
    lines = [line for line in result.output.splitlines() if line.startswith("warning:")]
    assert len(lines) == 1 and "no maintainer or license" in lines[0], result.output


def test_a_bad_maintainer_email_is_a_one_line_spec_error(tmp_path):
    path = _spec(tmp_path, "maintainer: {name: Jane Doe, email: jane at example}\n")
    with pytest.raises(SpecError) as caught:
        load_spec(path)
    text = str(caught.value)
    assert "\n" not in text and "maintainer.email" in text
    assert f":{len(path.read_text().splitlines())}" in text  # the line of the bad field


def test_a_spec_that_names_no_maintainer_on_purpose_builds_without_warning(tmp_path):
    """`maintainer: unnamed` (no source names one) with a licence: no warning, and package.xml
    keeps the placeholder maintainer; a spec that forgets still gets the warning."""
    path = _spec(tmp_path, "maintainer: unnamed\nlicense: Apache-2.0\n")
    robot = model_from_spec(str(path))
    assert robot.maintainer is None and robot.maintainer_unnamed
    assert ros2.package_warning(robot) is None
    forgot = model_from_spec(str(_spec(tmp_path, "license: Apache-2.0\n")))
    assert "no maintainer" in ros2.package_warning(forgot)
