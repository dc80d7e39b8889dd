"""A kit's models reference only files inside the kit (issue 24, check/references.py): a
mesh, texture, include or USD layer on the builder's disk, or climbing out of the kit, fails
`simkit check`; blocks copied from a URDF may name other packages (listed, not failed)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from simkit.check.kit import Kit
from simkit.check.references import check_references

SPEC = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"


@pytest.fixture
def kit(kit_factory, tmp_path) -> Path:
    """A copy of a small built kit, free to edit."""
    built = kit_factory(str(SPEC)).kit_dir
    return Path(shutil.copytree(built, tmp_path / built.name))


def _finding(kit: Path):
    (finding,) = check_references(Kit.open(kit))
    return finding


def _edit(path: Path, pattern: str, replacement: str) -> None:
    text = path.read_text()
    new = re.sub(pattern, replacement, text, count=1)
    assert new != text, f"{pattern} not in {path.name}"
    path.write_text(new)


def test_a_built_kit_references_only_its_own_files(kit):
    finding = _finding(kit)
    assert finding.ok, finding.detail
    assert "all inside the kit" in finding.detail


@pytest.mark.parametrize(
    ("model", "pattern", "replacement"),
    [
        ("urdf/planar_2r.urdf", r'filename="[^"]+"', 'filename="../../elsewhere/part.stl"'),
        ("urdf/planar_2r.urdf", r'filename="[^"]+"', 'filename="file:///etc/hostname"'),
        ("urdf/planar_2r.urdf", r'filename="[^"]+"', 'filename="package://other_pkg/a.stl"'),
        ("mjcf/planar_2r.xml", r'file="[^"]+"', 'file="/etc/hostname"'),
        ("sdf/planar_2r.sdf", r"<uri>[^<]+</uri>", "<uri>../../../elsewhere.stl</uri>"),
        ("usd/planar_2r.usda", r"\(\n", "(\n    subLayers = [@/tmp/elsewhere/layer.usda@]\n"),
    ],
    ids=["urdf-climbs", "urdf-file-uri", "urdf-other-package", "mjcf", "sdf", "usd-sublayer"],
)
def test_a_reference_outside_the_kit_fails(kit, model, pattern, replacement):
    _edit(kit / model, pattern, replacement)
    finding = _finding(kit)
    assert not finding.ok
    assert "outside the kit" in finding.detail and model in finding.detail, finding.detail


def test_copied_blocks_may_name_other_packages(kit):
    urdf = kit / "urdf" / "planar_2r.urdf"
    block = '<gazebo><plugin filename="$(find other_pkg)/lib/x.so" name="x"/></gazebo>'
    _edit(urdf, r"</robot>", block + "</robot>")
    finding = _finding(kit)
    assert finding.ok, finding.detail
    assert "external references in copied blocks" in finding.detail
    assert "$(find other_pkg)" in finding.detail
