"""The source comparison (issue 22, fidelity): an import keeps its expanded URDF beside the
spec with its digest and lists every intended difference; the build's `source` check re-reads
that file with yourdfpy and fails on any other difference, naming the joint or link."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml
from click.testing import CliRunner

from simkit.check.source import Allowed
from simkit.check.source.urdf import compare_robots, load_urdf
from simkit.errors import CheckFailed, SpecError
from simkit.importer import import_robot
from simkit.spec.validate import load_spec

BOX = '<geometry><box size="0.05 0.05 0.2"/></geometry>'


def _link(name: str, mass: str = "1.0") -> str:
    return (
        f'<link name="{name}"><inertial><mass value="{mass}"/>'
        '<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<visual>{BOX}</visual><collision>{BOX}</collision></link>"
    )


def _urdf(axis: str = "1 0 0", mass: str = "1.0", velocity: str = "2") -> str:
    return (
        '<?xml version="1.0"?>\n<robot name="src">\n'
        + _link("base")
        + "\n"
        + _link("arm", mass)
        + '\n<joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>'
        f'<origin xyz="0 0 0.2"/><axis xyz="{axis}"/>'
        f'<limit lower="-1" upper="1" effort="20" velocity="{velocity}"/></joint>\n</robot>\n'
    )


def _compare(tmp_path: Path, source: str, kit: str, differences=()) -> list[str]:
    (tmp_path / "a.urdf").write_text(source)
    (tmp_path / "b.urdf").write_text(kit)
    allowed = Allowed.of({"source_differences": list(differences)})
    found = compare_robots(load_urdf(tmp_path / "a.urdf"), load_urdf(tmp_path / "b.urdf"), allowed)
    return [f.detail for f in found if not f.ok]


def test_the_same_robot_passes_and_each_unlisted_difference_names_its_element(tmp_path):
    assert _compare(tmp_path, _urdf(), _urdf()) == []
    turned = _compare(tmp_path, _urdf(axis="0 1 0"), _urdf())
    assert len(turned) == 1 and "joint 'j1': axis (0, 1, 0)" in turned[0]
    heavier = _compare(tmp_path, _urdf(mass="1.1"), _urdf())
    assert len(heavier) == 1 and "link 'arm': mass 1.1" in heavier[0]
    faster = _compare(tmp_path, _urdf(velocity="3"), _urdf())
    assert len(faster) == 1 and "joint 'j1': velocity 3" in faster[0]


def test_a_listed_difference_passes_and_a_listed_rename_maps_the_names(tmp_path):
    listed = [{"what": "joints.j1.max_velocity", "reason": "a placeholder"}]
    assert _compare(tmp_path, _urdf(velocity="3"), _urdf(), listed) == []
    renamed = _urdf().replace('"arm"', '"arm_2"')
    missing = _compare(tmp_path, _urdf(), renamed)
    assert any("link 'arm' is missing" in m for m in missing)
    listed = [{"what": "links.arm.name", "reason": "renamed", "kit": "arm_2"}]
    assert _compare(tmp_path, _urdf(), renamed, listed) == []


def test_import_keeps_the_source_with_its_digest_and_lists_the_differences(tmp_path):
    (tmp_path / "r.urdf").write_text(_urdf(velocity="1000"))
    done = import_robot(tmp_path / "r.urdf", tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    kept = tmp_path / "out" / spec["source"]["file"]
    assert spec["source"]["file"] == "r.source.urdf" and kept.is_file()
    import hashlib

    assert spec["source"]["sha256"] == hashlib.sha256(kept.read_bytes()).hexdigest()
    whats = {d["what"]: d["reason"] for d in spec["source_differences"]}
    assert set(whats) == {"joints.j1.max_velocity", "links.world", "joints.base_fixed"}
    assert "velocity 1000 is a placeholder" in whats["joints.j1.max_velocity"]
    kept.unlink()  # the spec names a kept source that must exist
    with pytest.raises(SpecError, match=r"source\.file: source file not found"):
        load_spec(done.spec_path)


@pytest.mark.slow
def test_build_passes_and_fails_once_the_kept_source_is_changed(tmp_path):
    from simkit.cli import main
    from simkit.pipeline import build

    (tmp_path / "r.urdf").write_text(_urdf())
    done = import_robot(tmp_path / "r.urdf", tmp_path / "out")
    result = build(str(done.spec_path), tmp_path / "kits")
    names = {f.check for f in result.findings}
    assert {"source.digest", "source.links", "source.joints"} <= names
    doc = json.loads((result.kit_dir / "robot.json").read_text())
    assert doc["source"]["file"] == "r.source.urdf" and doc["source_differences"]
    kept = tmp_path / "out" / "r.source.urdf"
    original = kept.read_text()
    kept.write_text(original.replace('<axis xyz="1 0 0"/>', '<axis xyz="0 1 0"/>'))
    with pytest.raises(CheckFailed, match=r"joint 'j1': axis"):
        build(str(done.spec_path), tmp_path / "kits")
    arm = '<link name="arm"><inertial><mass value="1.0"/>'
    assert arm in original
    kept.write_text(original.replace(arm, arm.replace("1.0", "1.1")))
    with pytest.raises(CheckFailed, match=r"link 'arm': mass 1\.1"):
        build(str(done.spec_path), tmp_path / "kits")
    # `simkit check KIT --source URDF`: the same comparison on the built (unchanged) kit
    run = CliRunner().invoke(main, ["check", str(result.kit_dir), "--source", str(kept)])
    assert run.exit_code == CheckFailed.exit_code and "link 'arm': mass 1.1" in run.output
    kept.write_text(original)
    run = CliRunner().invoke(main, ["check", str(result.kit_dir), "--source", str(kept)])
    assert run.exit_code == 0, run.output


def test_inertia_is_compared_in_link_axes_whatever_frame_the_urdf_gives_it(tmp_path):
    """The source's inertial `rpy` 0 0 pi/2 swaps ixx and iyy in link axes: the kit writes the
    rotated tensor with rpy 0 (importer/translate/links.py), which is the same body."""
    tilted = _urdf().replace(
        '<link name="arm"><inertial><mass value="1.0"/>'
        '<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/>',
        '<link name="arm"><inertial><origin xyz="0 0 0.1" rpy="0 0 1.5707963267948966"/>'
        '<mass value="1.0"/><inertia ixx="0.001" iyy="0.003" izz="0.002" ixy="0" ixz="0" iyz="0"/>',
    )
    rotated = tilted.replace(' rpy="0 0 1.5707963267948966"', "").replace(
        'ixx="0.001" iyy="0.003"', 'ixx="0.003" iyy="0.001"'
    )
    assert tilted != _urdf() and rotated != tilted
    assert _compare(tmp_path, tilted, rotated) == []
    unrotated = _compare(tmp_path, tilted, tilted.replace(' rpy="0 0 1.5707963267948966"', ""))
    assert len(unrotated) == 1 and "link 'arm': inertia" in unrotated[0]
