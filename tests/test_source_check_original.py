"""`simkit check KIT --source ORIGINAL` takes the file the user imported (issue 38 item 2):
robot.json records the original's digest beside the kept copy's (a URDF is kept
re-serialised, a xacro expanded), and the xacro args; the check reads the original again as
the import read it, which must give the kept file. A changed original fails its digest.
Small handwritten files: a URDF with comments and odd formatting, a xacro, an MJCF."""

from __future__ import annotations

import hashlib
import json

import pytest
import yaml
from click.testing import CliRunner

from mjcf_models import arm, write
from simkit.check.kit import Kit
from simkit.check.source import check_source
from simkit.check.source.shared import digest
from simkit.cli import main
from simkit.importer import import_robot
from simkit.importer.read.options import ReadOptions

INERTIAL = (
    '<inertial><origin xyz="0 0 0.1"/><mass value="{mass}"/>'
    '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
)
BOX = '<visual><geometry><box size="0.05 0.05 0.2"/></geometry></visual>'
# comments, single quotes, odd spacing and blank lines: the kept copy is re-serialised
URDF = f"""<?xml version="1.0"?>
<!-- a comment the kept copy drops -->
<robot   name='odd' >

  <link name="base">{INERTIAL.format(mass=2)}{BOX}</link>   <!-- the base -->
  <link name='arm' >{INERTIAL.format(mass=1)}{BOX}</link>
  <joint name="j1"   type="revolute">
     <parent link="base"/>  <child link="arm"/>
     <origin xyz="0 0 0.2"/> <axis xyz="0 1 0"/>
     <limit lower="-1" upper="1" effort="20" velocity="2"/>
  </joint>
</robot>
"""
XACRO = f"""<?xml version="1.0"?>
<robot name="xa" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="mass" default="1"/>
  <!-- the arm mass comes from a xacro arg -->
  <link name="base">{INERTIAL.format(mass=2)}{BOX}</link>
  <link name="arm">{INERTIAL.format(mass="$(arg mass)")}{BOX}</link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="20" velocity="2"/></joint>
</robot>
"""
MJCF = arm(
    '<joint name="j1" axis="0 1 0" range="-1 1"/>'
    '<body name="tip" pos="0 0 0.2"><joint name="j2" axis="0 1 0" range="-1 1"/>'
    '<inertial pos="0 0 0" mass="0.5" diaginertia="0.001 0.001 0.001"/></body>'
)


def _check(kit_dir, original) -> tuple[int, str]:
    run = CliRunner().invoke(main, ["check", str(kit_dir), "--source", str(original)])
    return run.exit_code, run.output


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["urdf", "xacro", "mjcf"])
def test_check_takes_the_original_file_and_fails_a_changed_one(tmp_path, fmt):
    from simkit.pipeline import build

    folder = tmp_path / "src"
    folder.mkdir()
    reading = None
    if fmt == "urdf":
        original, changed = folder / "odd.urdf", URDF.replace('value="1"', 'value="1.5"')
        original.write_text(URDF)
    elif fmt == "xacro":
        original, changed = folder / "xa.urdf.xacro", XACRO.replace('"0 1 0"', '"1 0 0"')
        original.write_text(XACRO)
        reading = ReadOptions(xacro_args=(("mass", "1.25"),))
    else:
        original = write(folder, MJCF, "arm.xml")
        changed = MJCF.replace('mass="0.5"', 'mass="0.7"')
    done = import_robot(original, tmp_path / "out", reading=reading)
    recorded = yaml.safe_load(done.spec_path.read_text())["source"]
    assert recorded["format"] == fmt
    digest_of = hashlib.sha256(original.read_bytes()).hexdigest()
    if fmt == "mjcf":  # kept byte for byte: the kept digest is the original's
        assert recorded["sha256"] == digest_of and "original" not in recorded
    else:
        assert recorded["original"] == digest_of != recorded["sha256"]
    if fmt == "xacro":
        assert recorded["args"] == {"mass": "1.25"}
    result = build(str(done.spec_path), tmp_path / "kits")
    assert all(f.ok for f in result.findings if f.check.startswith("source")), [
        f.line() for f in result.findings if not f.ok
    ]
    robot_json = json.loads((result.kit_dir / "robot.json").read_text())
    assert robot_json["source"]["format"] == fmt
    code, output = _check(result.kit_dir, original)  # the untouched original
    assert code == 0 and "FAIL" not in output, output
    kept = tmp_path / "out" / recorded["file"]  # the kept copy still passes too
    assert _check(result.kit_dir, kept)[0] == 0
    original.write_text(changed)
    code, output = _check(result.kit_dir, original)
    assert code != 0 and "FAIL source.digest" in output, output


def _kit(tmp_path, source: dict) -> Kit:
    folder = tmp_path / "kit"
    folder.mkdir()
    (folder / "robot.json").write_text(json.dumps({"source": source}))
    given = tmp_path / "given.urdf"
    given.write_text("<robot name='r'/>")
    return Kit(folder, given)


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def test_the_original_must_read_as_the_import_read_it(tmp_path):
    """The given file is the original: its remade kept file must give the kept digest, and
    the recorded args reach the remake."""
    kept = b"<robot name='r'><link name='a'/></robot>\n"
    given = b"<robot name='r'/>"
    kit = _kit(tmp_path, {"file": "r.source.urdf", "sha256": _sha(kept), "original": _sha(given),
                          "args": {"a": "1"}})  # fmt: skip
    seen = []
    found, data = digest(kit, kit.source, lambda path, args: seen.append(args) or kept)
    assert [f.ok for f in found] == [True] and data == kept and seen == [{"a": "1"}]
    found, data = digest(kit, kit.source, lambda path, args: b"<robot name='other'/>")
    assert [f.ok for f in found] == [False] and "does not read as the import" in found[0].line()


def test_a_file_that_is_neither_fails_naming_both_digests(tmp_path):
    kit = _kit(tmp_path, {"file": "r.source.urdf", "sha256": "a" * 64, "original": "b" * 64})
    found, _data = digest(kit, kit.source, lambda path, args: b"")
    line = found[0].line()
    assert not found[0].ok and "changed after the import" in line and "bbbbbbbbbbbb" in line
    assert check_source(kit)[0].check == "source.digest"
