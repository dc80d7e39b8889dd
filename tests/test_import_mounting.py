"""An undeclared parent above the root is the frame the robot is mounted on (issue 32,
class 1): accepted with one report line, and the kit built from it passes its checks (the
source check included); an undeclared name inside the tree is still refused in one line."""

from __future__ import annotations

import pytest
import yaml

from simkit.errors import SpecError
from simkit.importer import import_robot
from urdf_parts import joint, link, write


def test_an_undeclared_parent_above_the_root_is_the_mounting_frame(tmp_path):
    from simkit.pipeline import build

    urdf = write(
        tmp_path,
        "arm",
        joint("mount_joint", "world", "base", "fixed"),  # `world` is declared nowhere
        link("base"),
        link("upper"),
        joint("shoulder", "base", "upper"),
    )
    done = import_robot(urdf, tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert spec["root"] == "world"
    mount = next(j for j in spec["joints"] if j["name"] == "mount_joint")
    assert (mount["parent"], mount["child"], mount["xyz"]) == ("world", "base", [0, 0, 0.2])
    said = [line for line in done.lines if "not declared" in line]
    assert len(said) == 1 and "joint[mount_joint]" in said[0] and "'world'" in said[0]
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert any(f.check == "source.joints" and f.ok for f in result.findings)


def test_a_movable_mount_on_an_undeclared_frame_keeps_its_joint(tmp_path):
    urdf = write(
        tmp_path,
        "hand",
        link("palm"),
        link("finger"),
        joint("wrist", "hand_of_another_robot", "palm"),
        joint("knuckle", "palm", "finger"),
    )
    spec = yaml.safe_load(import_robot(urdf, tmp_path / "out").spec_path.read_text())
    assert spec["root"] == "hand_of_another_robot"
    assert [j["name"] for j in spec["joints"]] == ["wrist", "knuckle"]


@pytest.mark.parametrize(
    ("body", "message"),
    [
        # the undeclared name is a child: inside the tree
        ([link("base"), joint("j1", "base", "ghost")], "unknown child link 'ghost'"),
        # two undeclared parents: two roots
        (
            [link("a"), link("b"), joint("j1", "world", "a"), joint("j2", "table", "b")],
            "unknown parent link",
        ),
        # one undeclared parent of a second root besides a declared one
        (
            [link("a"), link("b"), link("c"), joint("j1", "a", "b"), joint("j2", "x", "c")],
            "more than one root",
        ),
    ],
    ids=["child", "two_parents", "second_root"],
)
def test_an_undeclared_name_inside_the_tree_is_refused_in_one_line(tmp_path, body, message):
    with pytest.raises(SpecError) as refused:
        import_robot(write(tmp_path, "arm", *body), tmp_path / "out")
    assert message in str(refused.value) and "\n" not in str(refused.value)
    assert not (tmp_path / "out").exists()  # the refused import wrote nothing
