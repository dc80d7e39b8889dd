"""The MJCF source proof (issue 31): MuJoCo compiles the source and the kit's MJCF; joints,
masses and inertias, FK at seeded configurations and actuator force bounds must agree or be
listed. A tampered axis, mass or actuator bound in the kit fails, naming it; a changed
source fails its digest and is not compiled."""

from __future__ import annotations

import hashlib
import json

import pytest

from mjcf_models import arm, write
from simkit.check.kit import Kit
from simkit.check.source import check_source

SOURCE = arm(
    '<joint name="j1" axis="0 1 0" pos="0 0 0.02" ref="0.3" range="-1 1"/>'
    '<body name="tip" pos="0 0 0.2"><joint name="j2" type="slide" axis="0 0 1" range="0 0.1"/>'
    '<inertial pos="0 0 0" mass="0.5" diaginertia="0.001 0.001 0.001"/></body>',
    '<actuator><motor name="m1" joint="j1" gear="10" ctrlrange="-1 1"/></actuator>',
)


def _kit(tmp_path, kit_text: str, listed=()) -> Kit:
    """A kit folder holding only what the source check reads: robot.json and its MJCF."""
    source = write(tmp_path / "src", SOURCE, "arm.xml")
    folder = tmp_path / "kit"
    write(folder, kit_text, "arm.xml")
    doc = {
        "files": {"mjcf": "arm.xml"},
        "source": {"file": "arm.xml", "sha256": hashlib.sha256(source.read_bytes()).hexdigest()},
        "source_differences": [{"what": w, "reason": "test"} for w in listed],
    }
    (folder / "robot.json").write_text(json.dumps(doc))
    return Kit(folder, source)


def _failed(kit: Kit) -> list[str]:
    return [f.line() for f in check_source(kit) if not f.ok]


def test_the_same_model_passes_every_comparison(tmp_path):
    findings = check_source(_kit(tmp_path, SOURCE))
    assert {f.check for f in findings} >= {"source.joints", "source.links", "source.fk"}
    assert all(f.ok for f in findings), [f.line() for f in findings]


def test_a_tampered_axis_fails(tmp_path):
    failed = _failed(_kit(tmp_path, SOURCE.replace('axis="0 1 0"', 'axis="1 0 0"')))
    assert any("joint 'j1': axis" in line for line in failed)
    assert any("source.fk" in line for line in failed)


def test_a_tampered_mass_fails_unless_listed(tmp_path):
    tampered = SOURCE.replace('mass="0.5"', 'mass="0.6"')
    assert any("link 'tip': mass 0.5" in line for line in _failed(_kit(tmp_path, tampered)))
    assert not _failed(_kit(tmp_path / "listed", tampered, listed=["links.tip.mass"]))


def test_a_tampered_actuator_bound_fails(tmp_path):
    failed = _failed(_kit(tmp_path, SOURCE.replace('gear="10"', 'gear="12"')))
    assert any("joint 'j1': actuator force bound 10" in line for line in failed)


def test_a_changed_kept_file_fails_the_digest(tmp_path):
    kit = _kit(tmp_path, SOURCE)
    kit.source.write_text(SOURCE.replace('range="-1 1"', 'range="-2 2"'))
    assert any("source.digest" in line for line in _failed(kit))


@pytest.mark.slow
def test_an_imported_mjcf_builds_with_its_source_proof(tmp_path):
    from click.testing import CliRunner

    from simkit.cli import main
    from simkit.importer import import_robot
    from simkit.pipeline import build

    source = write(tmp_path / "src", SOURCE, "arm.xml")
    done = import_robot(source, tmp_path / "out")
    result = build(str(done.spec_path), tmp_path / "kits")
    names = {f.check for f in result.findings if f.ok}
    assert {"source.digest", "source.joints", "source.links", "source.fk"} <= names
    run = CliRunner().invoke(main, ["check", str(result.kit_dir), "--source", str(source)])
    assert run.exit_code == 0, run.output
    # a changed source is not the file the import read: it fails its digest and is never
    # compiled (it may name any file on the machine)
    source.write_text(SOURCE.replace('axis="0 1 0"', 'axis="1 0 0"'))
    run = CliRunner().invoke(main, ["check", str(result.kit_dir), "--source", str(source)])
    assert "FAIL source.digest" in run.output and run.exit_code != 0
    assert "source.joints" not in run.output
