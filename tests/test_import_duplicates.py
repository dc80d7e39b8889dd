"""A link defined twice with identical content is one link (issue 32, class 2): accepted
with one report line, and the kit passes its checks; two different definitions of a name are
refused in one line naming the second."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from simkit.errors import SpecError
from simkit.importer import import_robot

BOX = '<geometry><box size="0.05 0.05 0.2"/></geometry>'


def _link(name: str, mass: str = "1") -> str:
    return (
        f'<link name="{name}">\n  <inertial><mass value="{mass}"/><inertia ixx="0.004" '
        'iyy="0.004" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>\n'
        f'  <visual><origin xyz="0 0 0.1"/>{BOX}</visual>\n'
        f'  <collision><origin xyz="0 0 0.1"/>{BOX}</collision>\n</link>'
    )


JOINT = (
    '<joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>'
    '<origin xyz="0 0 0.2"/><axis xyz="1 0 0"/>'
    '<limit lower="-1" upper="1" effort="20" velocity="2"/></joint>'
)


def _write(tmp_path: Path, *body: str) -> Path:
    urdf = tmp_path / "dup.urdf"
    urdf.write_text(
        '<?xml version="1.0"?>\n<robot name="dup">\n' + "\n".join(body) + "\n</robot>\n"
    )
    return urdf


def test_an_identical_duplicate_link_is_accepted_with_one_line(tmp_path):
    from simkit.pipeline import build

    # the copy differs only in whitespace, as an include expanded twice would
    copy = _link("arm").replace("\n  ", "\n      ")
    done = import_robot(_write(tmp_path, _link("base"), _link("arm"), JOINT, copy), tmp_path / "o")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert [link["name"] for link in spec["links"]] == ["base", "arm"]
    said = [line for line in done.lines if "defined twice" in line]
    assert len(said) == 1 and "link[arm]" in said[0] and "line 8" in said[0], said
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert any(f.check == "source.links" and f.ok for f in result.findings)


def test_an_identical_duplicate_joint_is_accepted(tmp_path):
    done = import_robot(_write(tmp_path, _link("base"), _link("arm"), JOINT, JOINT), tmp_path / "o")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert [j["name"] for j in spec["joints"]] == ["base_fixed", "hinge"]


def test_a_different_duplicate_link_is_refused_in_one_line(tmp_path):
    body = (_link("base"), _link("arm"), JOINT, _link("arm", mass="2"))
    with pytest.raises(
        SpecError, match=r"dup\.urdf:14: link\[arm\]: .* defined twice, differently"
    ):
        import_robot(_write(tmp_path, *body), tmp_path / "o")
