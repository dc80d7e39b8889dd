"""The source proof reads the composed USD stage (issue 33, check/source/kit_usd.py): each
link's mass and each movable joint's type and limits in the kit's entry USD, composed with
its payloads, agree with the imported URDF's. A tampered physics payload fails."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from simkit.check.kit import Kit
from simkit.check.source import check_source
from simkit.importer import import_robot
from simkit.kitio import layout
from urdf_parts import joint, link, write


@pytest.fixture(scope="module")
def kit(tmp_path_factory) -> Path:
    from simkit.pipeline import build

    folder = tmp_path_factory.mktemp("source_usd")
    body = (
        link("base", mass="3"),
        link("upper", mass="2"),
        link("lower", mass="1.5"),
        joint("shoulder", "base", "upper"),
        joint("elbow", "upper", "lower", limit='lower="-0.5" upper="2" effort="40" velocity="2"'),
    )
    done = import_robot(write(folder, "arm2", *body), folder / "out")
    return build(str(done.spec_path), folder / "kits").kit_dir


def _source_usd(kit: Path, original: Path | None = None) -> list:
    """source.usd findings, with the source the import kept beside the spec (found from the
    `original` kit's place when `kit` is a copy)."""
    (source,) = ((original or kit).parent.parent / "out").glob("*.source.urdf")
    return [f for f in check_source(Kit.open(kit, source)) if f.check == "source.usd"]


def _tampered(kit: Path, tmp_path: Path, pattern: str, replacement: str) -> Path:
    import shutil

    copy = tmp_path / kit.name
    shutil.copytree(kit, copy)
    physics = copy / layout.usd_payload(copy.name.removesuffix("_description"), "physics.usda")
    text, count = re.subn(pattern, replacement, physics.read_text(), count=1)
    assert count == 1
    physics.write_text(text)
    return copy


def test_the_composed_stage_agrees_with_the_source(kit):
    found = _source_usd(kit)
    assert found and all(f.ok for f in found), [f.line() for f in found]
    assert "3 link masses and 2 movable joints" in found[0].line()


def test_a_tampered_mass_in_the_physics_payload_fails(kit, tmp_path):
    copy = _tampered(kit, tmp_path, r"(float physics:mass = )[0-9.e+-]+", r"\g<1>9.5")
    failures = [f.line() for f in _source_usd(copy, kit) if not f.ok]
    assert any("mass" in line and "in the USD" in line for line in failures), failures


def test_a_tampered_joint_limit_fails(kit, tmp_path):
    copy = _tampered(kit, tmp_path, r"(float physics:upperLimit = )[0-9.e+-]+", r"\g<1>10")
    failures = [f.line() for f in _source_usd(copy, kit) if not f.ok]
    assert any("limits" in line for line in failures), failures


def test_a_placeholder_span_the_kit_makes_continuous_is_a_listed_difference(tmp_path):
    """Revolute limits of +-1e16 rad (a spinning rotor's placeholder) become a continuous
    joint, listed in source_differences; the USD has no limits there, and source.usd
    accepts the listed difference."""
    from simkit.pipeline import build

    body = (
        link("base", mass="3"),
        link("rotor", mass="0.5"),
        joint("spin", "base", "rotor", limit='lower="-1e16" upper="1e16" effort="5" velocity="50"'),
    )
    done = import_robot(write(tmp_path, "prop", *body), tmp_path / "out")
    kit = build(str(done.spec_path), tmp_path / "kits").kit_dir
    found = _source_usd(kit)
    assert found and all(f.ok for f in found), [f.line() for f in found]
