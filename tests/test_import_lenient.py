"""Lenient reading (issue 22): the messy but common URDF forms PyBullet reads are read the
same way, one report line each; `--strict` refuses each of them in one line."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner

from simkit.cli import main
from simkit.errors import SpecError
from simkit.importer import import_robot
from simkit.importer.read.options import ReadOptions

STL = Path(__file__).resolve().parent / "specs" / "urdf" / "pkg_demo" / "meshes" / "bracket.stl"
INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
)
ROBOT = f"""<?xml version="1.0"?>
<robot name="r">
  <link name="base">{INERTIAL}
    <visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual>
  </link>
  <link name="arm">{INERTIAL}
    ARM_GEOMETRY
  </link>
  <joint name="j" type="revolute">
    <parent link="base"/><child link="arm"/>
    <origin xyz="XYZ" rpy="RPY"/><axis xyz="0 0 1"/>
    <limit lower="LOWER" upper="UPPER" effort="10" velocity="1"/>
  </joint>
</robot>
"""
BOX = '<visual><origin xyz="0 0 0.1"/><geometry><box size="0.05 0.05 0.2"/></geometry></visual>'
PLAIN = {
    "XYZ": "0 0 0.1",
    "RPY": "0 0 0",
    "LOWER": "-1",
    "UPPER": "1",
    "ARM_GEOMETRY": BOX,
}


def _urdf(tmp_path: Path, text: str | bytes) -> Path:
    """`text` as pkg/urdf/r.urdf beside pkg/meshes/part.stl, in a package (package.xml)."""
    (tmp_path / "pkg" / "urdf").mkdir(parents=True, exist_ok=True)
    (tmp_path / "pkg" / "meshes").mkdir(exist_ok=True)
    (tmp_path / "pkg" / "package.xml").write_text("<package><name>pkg</name></package>")
    shutil.copy(STL, tmp_path / "pkg" / "meshes" / "part.stl")
    path = tmp_path / "pkg" / "urdf" / "r.urdf"
    path.write_bytes(text.encode() if isinstance(text, str) else text)
    return path


def _robot(**changes: str) -> str:
    text = ROBOT
    for key, value in {**PLAIN, **changes}.items():
        text = text.replace(key, value)
    return text


def _joint(spec_path: Path) -> dict:
    spec = yaml.safe_load(spec_path.read_text())
    return next(j for j in spec["joints"] if j["name"] == "j")


CASES = {
    "version 0.0": (
        _robot().replace('version="1.0"', 'version="0.0"'),
        "r.urdf:1: xml: changed: XML declaration version '0.0': read as XML 1.0",
    ),
    "declaration after blank lines": (
        "\n\n" + _robot(),
        "r.urdf:3: xml: changed: XML declaration on line 3, after blank lines: ignored",
    ),
    "content after </robot>": (
        _robot() + "\x00\n",
        "r.urdf:15: xml: changed: content after the root element's end ignored (line 15)",
    ),
    "four-number rpy": (
        _robot(RPY="0 0 0.5 0"),
        "r.urdf:11: origin: changed: 'rpy' has more than 3 numbers ('0 0 0.5 0'): the first 3",
    ),
    "commas between numbers": (
        _robot(XYZ="0, 0, 0.1"),
        "r.urdf:11: origin: changed: 'xyz' is '0, 0, 0.1': read as '0 0 0.1'",
    ),
    "trailing dot": (
        _robot(LOWER="-1.0."),
        "r.urdf:12: limit: changed: 'lower' is '-1.0.': read as '-1'",
    ),
    "lower > upper": (
        _robot(LOWER="1", UPPER="-1"),
        "r.urdf:12: limit: changed: lower > upper, which Bullet reads as no limit",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_lenient_forms_are_read_and_reported_and_strict_refuses(tmp_path, case):
    text, line = CASES[case]
    path = _urdf(tmp_path, text)
    done = import_robot(path, tmp_path / "out")
    assert any(line in x for x in done.lines)
    joint = _joint(done.spec_path)
    assert joint["xyz"] == [0, 0, 0.1]
    if case == "four-number rpy":
        assert joint["rpy"] == [0, 0, 0.5]
    if case == "lower > upper":
        assert joint["type"] == "continuous" and "lower" not in joint
    elif case == "trailing dot":
        assert (joint["lower"], joint["upper"]) == (-1, 1)
    with pytest.raises(SpecError) as err:
        import_robot(path, tmp_path / "strict", strict=True)
    where = line.split(": changed: ")[0].split(":")[1]
    assert str(err.value).startswith(f"{path}:{where}: ")
    assert str(err.value).endswith("(--strict refuses it)") and "\n" not in str(err.value)


def test_a_four_number_scale_takes_the_first_three(tmp_path):
    mesh = '<visual><geometry><mesh filename="../meshes/part.stl" scale="2 2 2 1"/></geometry>'
    mesh += "</visual>"
    done = import_robot(_urdf(tmp_path, _robot(ARM_GEOMETRY=mesh)), tmp_path / "out")
    assert any("'scale' has more than 3 numbers ('2 2 2 1'): the first 3" in x for x in done.lines)
    assert done.meshes == 1


def test_optenv_in_a_urdf_takes_its_default_unless_allowed(tmp_path, monkeypatch):
    path = _urdf(tmp_path, _robot(XYZ="$(optenv SIMKIT_TEST_XYZ 0 0 0.1)"))
    monkeypatch.setenv("SIMKIT_TEST_XYZ", "0 0 0.7")
    done = import_robot(path, tmp_path / "a")
    assert _joint(done.spec_path)["xyz"] == [0, 0, 0.1]  # set, but not allowed
    assert any(
        "$(optenv SIMKIT_TEST_XYZ) left in a .urdf: its default '0 0 0.1'" in x for x in done.lines
    )
    allowed = import_robot(
        path, tmp_path / "b", reading=ReadOptions(allow_env=("SIMKIT_TEST_XYZ",))
    )
    assert _joint(allowed.spec_path)["xyz"] == [0, 0, 0.7]
    with pytest.raises(SpecError, match=r"r\.urdf:11: origin: \$\(optenv SIMKIT_TEST_XYZ\)"):
        import_robot(path, tmp_path / "c", strict=True)


def test_arg_in_a_urdf_takes_the_xacro_arg_value(tmp_path):
    path = _urdf(tmp_path, _robot(XYZ="0 0 $(arg height)"))
    with pytest.raises(SpecError, match=r"r\.urdf:11: .*pass --xacro-arg height:=VALUE"):
        import_robot(path, tmp_path / "a")
    result = CliRunner().invoke(
        main, ["import", str(path), "--out", str(tmp_path / "b"), "--xacro-arg", "height:=0.3"]
    )
    assert result.exit_code == 0, result.output
    assert _joint(tmp_path / "b" / "r.yaml")["xyz"] == [0, 0, 0.3]
    bad = CliRunner().invoke(
        main, ["import", str(path), "--out", str(tmp_path / "c"), "--xacro-arg", "height"]
    )
    assert bad.exit_code == 2 and "'height' is not NAME:=VALUE" in bad.output


def test_a_missing_mesh_drops_that_geometry_only(tmp_path):
    geometry = (
        '<visual><geometry><mesh filename="../meshes/gone.stl"/></geometry></visual>\n'
        '<collision><geometry><box size="0.05 0.05 0.2"/></geometry></collision>'
    )
    path = _urdf(tmp_path, _robot(ARM_GEOMETRY=geometry))
    done = import_robot(path, tmp_path / "out")
    assert (
        "r.urdf:7: mesh: changed: mesh file not found: ../meshes/gone.stl: this visual is left out"
        in done.lines
    )
    arm = next(
        link
        for link in yaml.safe_load(done.spec_path.read_text())["links"]
        if link["name"] == "arm"
    )
    assert [s["shape"] for s in arm["solid"]] == ["box"]  # the collision box, kept
    assert arm["solid"][0]["size"] == [0.05, 0.05, 0.2]
    with pytest.raises(
        SpecError, match=r"r\.urdf:7: mesh: mesh file not found: \.\./meshes/gone\.stl"
    ):
        import_robot(path, tmp_path / "strict", strict=True)


def test_a_link_whose_only_mesh_is_missing_gets_an_estimated_box(tmp_path):
    geometry = '<visual><geometry><mesh filename="package://nowhere/gone.stl"/></geometry></visual>'
    done = import_robot(_urdf(tmp_path, _robot(ARM_GEOMETRY=geometry)), tmp_path / "out")
    line = next(x for x in done.lines if "unknown package 'nowhere'" in x)
    assert "the link has no other geometry, so it gets an estimated box" in line
    arm = next(
        link
        for link in yaml.safe_load(done.spec_path.read_text())["links"]
        if link["name"] == "arm"
    )
    assert arm["solid"][0]["shape"] == "box" and min(arm["solid"][0]["size"]) >= 0.01


def test_substitutions_in_kept_gazebo_blocks_stay_verbatim(tmp_path):
    text = _robot().replace(
        "</robot>",
        '  <gazebo><plugin name="$(arg ns)_control" filename="x.so"/></gazebo>\n</robot>',
    )
    done = import_robot(_urdf(tmp_path, text), tmp_path / "out")
    assert "$(arg ns)_control" in done.spec_path.read_text()
