"""An undeclared parent above the root is the frame the robot is mounted on (issue 32,
class 1): accepted with one report line, and the kit built from it passes its checks (the
source check included); an undeclared name inside the tree is still refused in one line."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from simkit.errors import SpecError
from simkit.importer import import_robot

BOX = '<geometry><box size="0.05 0.05 0.2"/></geometry>'


def _link(name: str) -> str:
    return (
        f'<link name="{name}"><inertial><mass value="1"/><inertia ixx="0.004" iyy="0.004" '
        'izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>'
        f'<visual><origin xyz="0 0 0.1"/>{BOX}</visual>'
        f'<collision><origin xyz="0 0 0.1"/>{BOX}</collision></link>'
    )


def _joint(name: str, parent: str, child: str, kind: str = "revolute") -> str:
    limit = '<limit lower="-1" upper="1" effort="20" velocity="2"/>' if kind != "fixed" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 0.2" rpy="0 0 0.5"/><axis xyz="1 0 0"/>{limit}</joint>'
    )


def _write(tmp_path: Path, *body: str) -> Path:
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(
        '<?xml version="1.0"?>\n<robot name="arm">\n' + "\n".join(body) + "\n</robot>\n"
    )
    return urdf


def test_an_undeclared_parent_above_the_root_is_the_mounting_frame(tmp_path):
    from simkit.pipeline import build

    urdf = _write(
        tmp_path,
        _joint("mount_joint", "world", "base", "fixed"),  # `world` is declared nowhere
        _link("base"),
        _link("upper"),
        _joint("shoulder", "base", "upper"),
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
    urdf = _write(
        tmp_path,
        _link("palm"),
        _link("finger"),
        _joint("wrist", "hand_of_another_robot", "palm"),
        _joint("knuckle", "palm", "finger"),
    )
    spec = yaml.safe_load(import_robot(urdf, tmp_path / "out").spec_path.read_text())
    assert spec["root"] == "hand_of_another_robot"
    assert [j["name"] for j in spec["joints"]] == ["wrist", "knuckle"]


@pytest.mark.parametrize(
    ("body", "message"),
    [
        # the undeclared name is a child: inside the tree
        ([_link("base"), _joint("j1", "base", "ghost")], "unknown child link 'ghost'"),
        # two undeclared parents: two roots
        (
            [_link("a"), _link("b"), _joint("j1", "world", "a"), _joint("j2", "table", "b")],
            "unknown parent link",
        ),
        # one undeclared parent of a second root besides a declared one
        (
            [_link("a"), _link("b"), _link("c"), _joint("j1", "a", "b"), _joint("j2", "x", "c")],
            "more than one root",
        ),
    ],
    ids=["child", "two_parents", "second_root"],
)
def test_an_undeclared_name_inside_the_tree_is_refused_in_one_line(tmp_path, body, message):
    with pytest.raises(SpecError) as refused:
        import_robot(_write(tmp_path, *body), tmp_path / "out")
    assert message in str(refused.value) and "\n" not in str(refused.value)
    assert not (tmp_path / "out").exists()  # the refused import wrote nothing
