"""A link with two parent joints (issue 42, class 8): an end effector fixed both to the arm's
last link and to the base is a closed loop. The tree is built from the link's first joint in
document order; the later joint closes the loop as a weld (spec `loops`, at the pose the
tree gives at home), with one report line, listed in `source_differences`; the kit built
from it carries the weld in its MJCF and USD, and passes its checks (the source check
included: the kept URDF still holds both joints)."""

from __future__ import annotations

import json

import pytest
import yaml

from simkit.check.kit import Kit
from simkit.check.loops import check_loops
from simkit.check.source import check_source
from simkit.importer import import_robot
from urdf_parts import joint, link, write


def _looped(tmp_path, frame: str = "base"):
    """base -> upper (revolute) -> tip (fixed), and tip fixed to `frame` too (the loop):
    the base, or an undeclared world the base is bolted to (the mounting frame)."""
    mount = [joint("mount", "world", "base", "fixed")] if frame == "world" else []
    return write(
        tmp_path,
        "looped",
        *mount,
        link("base"),
        link("upper"),
        link("tip", mass="0.2"),
        joint("shoulder", "base", "upper"),
        joint("tip_mount", "upper", "tip", "fixed"),
        joint("tip_to_base", frame, "tip", "fixed"),
    )


def test_the_first_joint_builds_the_tree_and_the_second_is_listed(tmp_path):
    done = import_robot(_looped(tmp_path), tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    joints = {j["name"]: j for j in spec["joints"]}
    assert "tip_to_base" not in joints
    assert (joints["tip_mount"]["parent"], joints["tip_mount"]["child"]) == ("upper", "tip")
    said = [line for line in done.lines if "closed loop" in line]
    assert len(said) == 1 and "joint[tip_to_base]" in said[0] and "'tip_mount'" in said[0]
    assert "weld" in said[0]
    listed = {d["what"]: d["reason"] for d in spec["source_differences"]}
    assert "closed loop" in listed["joints.tip_to_base"]
    (loop,) = spec["loops"]
    assert (loop["name"], loop["type"], loop["link1"], loop["link2"]) == (
        "tip_to_base",
        "weld",
        "base",
        "tip",
    )
    # the tree at home (shoulder at 0): tip 0.4 m above the base, turned 1 rad about z
    assert loop["xyz"] == pytest.approx([0, 0, 0.4], abs=1e-9)
    assert loop["rpy"] == pytest.approx([0, 0, 1.0], abs=1e-9)


def test_a_movable_second_joint_is_said_to_be_locked(tmp_path):
    urdf = _looped(tmp_path).read_text()
    second = urdf[urdf.index('<joint name="tip_to_base"') :]
    pinned = second.replace('type="fixed"', 'type="revolute"').replace(
        "</joint>", '<limit lower="-1" upper="1" effort="5" velocity="1"/></joint>'
    )
    (tmp_path / "looped.urdf").write_text(urdf.replace(second, pinned))
    done = import_robot(tmp_path / "looped.urdf", tmp_path / "out")
    (said,) = [line for line in done.lines if "closed loop" in line]
    assert "its revolute motion is locked" in said
    assert [lp["name"] for lp in yaml.safe_load(done.spec_path.read_text())["loops"]] == [
        "tip_to_base"
    ]


def test_a_loop_named_outside_the_name_grammar_is_spelled_in_it(tmp_path):
    urdf = _looped(tmp_path).read_text().replace('"tip_to_base"', '"tip-to/base"')
    (tmp_path / "looped.urdf").write_text(urdf)
    done = import_robot(tmp_path / "looped.urdf", tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert [loop["name"] for loop in spec["loops"]] == ["tip_to_base"]
    assert "joints.tip-to/base" in {d["what"] for d in spec["source_differences"]}


@pytest.mark.slow
@pytest.mark.parametrize("frame", ["base", "world"])
def test_the_looped_robot_builds_a_checked_kit(tmp_path, frame):
    from simkit.pipeline import build

    done = import_robot(_looped(tmp_path, frame), tmp_path / "out")
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    passed = {f.check for f in result.findings if f.ok}
    assert {"source.joints", "source.loops", "loops.mjcf", "loops.hold", "usd.loops"} <= passed
    robot = json.loads((result.kit_dir / "robot.json").read_text())
    assert any(d["what"] == "joints.tip_to_base" for d in robot["source_differences"])
    # the tip 0.4 m above the base, which the world mount lifts 0.2 m (MuJoCo's world body)
    body1, z = ("base", "0.4") if frame == "base" else ("world", "0.6")
    mjcf = result.kit_dir / "mjcf/looped.xml"
    text = mjcf.read_text()
    weld = f'<weld name="tip_to_base" body1="{body1}" body2="tip" relpose="0 0 {z} '
    assert weld in text
    mjcf.write_text(text.replace(weld, weld.replace(z, z + "1")))  # tampered by 1 cm
    failed = [f.check for f in check_loops(Kit.open(result.kit_dir)) if not f.ok]
    assert failed == ["loops.mjcf"]
    # robot.json's loop moved to another link: the source check compares it with the source
    doc = json.loads((result.kit_dir / "robot.json").read_text())
    doc["loops"][0]["link1"] = "upper"
    (result.kit_dir / "robot.json").write_text(json.dumps(doc))
    kept = done.spec_path.parent / "looped.source.urdf"
    (finding,) = [f for f in check_source(Kit.open(result.kit_dir, kept)) if "loops" in f.check]
    assert not finding.ok and "joins 'upper' and 'tip'" in finding.detail
