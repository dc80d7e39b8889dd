"""A link defined twice with identical content is one link (issue 32, class 2): accepted
with one report line, and the kit passes its checks; two different definitions of a name are
refused in one line naming the second."""

from __future__ import annotations

import pytest
import yaml

from simkit.errors import SpecError
from simkit.importer import import_robot
from urdf_parts import joint, link, write

HINGE = joint("hinge", "base", "arm")


def test_an_identical_duplicate_link_is_accepted_with_one_line(tmp_path):
    from simkit.pipeline import build

    copy = link("arm", gap="\n      ")  # whitespace aside, the same: an include expanded twice
    urdf = write(tmp_path, "dup", link("base"), link("arm", gap="\n  "), HINGE, copy)
    done = import_robot(urdf, tmp_path / "o")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert [item["name"] for item in spec["links"]] == ["base", "arm"]
    said = [line for line in done.lines if "defined twice" in line]
    assert len(said) == 1 and "link[arm]" in said[0] and "line 4" in said[0], said
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert any(f.check == "source.links" and f.ok for f in result.findings)


def test_an_identical_duplicate_joint_is_accepted(tmp_path):
    urdf = write(tmp_path, "dup", link("base"), link("arm"), HINGE, HINGE)
    spec = yaml.safe_load(import_robot(urdf, tmp_path / "o").spec_path.read_text())
    assert [j["name"] for j in spec["joints"]] == ["base_fixed", "hinge"]


def test_a_different_duplicate_link_is_refused_in_one_line(tmp_path):
    urdf = write(tmp_path, "dup", link("base"), link("arm"), HINGE, link("arm", mass="2"))
    with pytest.raises(SpecError, match=r"dup\.urdf:6: link\[arm\]: .* defined twice, differently"):
        import_robot(urdf, tmp_path / "o")
