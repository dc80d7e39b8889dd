"""Kinematic loops closed by a weld (spec `loops`, issue 42 class 8): a hand-written planar
2R arm whose forearm is also welded to the base (a strut) keeps its tree, and the kit closes
the loop where a format can: the MJCF's `<equality><weld>`, the USD's fixed joint excluded
from the articulation; the URDF and SDFormat keep the tree and say so; robot.json lists the
loop; the SRDF and the MJCF exclude the welded pair's contacts. The checks read the written
files: a tampered relpose fails. The spec refuses a loop it cannot close, in one line."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest
import yaml

from simkit.check.kit import Kit
from simkit.check.loops import check_loops
from simkit.errors import SpecError
from simkit.kitio import layout
from simkit.spec.validate import load_spec

PLANAR = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
#: link_2 in base_link's frame at home (both joints at 0): 0.3 m out, 0.08 m up
STRUT = {"name": "strut", "link1": "base_link", "link2": "link_2", "xyz": [0.3, 0, 0.08]}


def _spec(tmp_path: Path, loops: list[dict], name: str = "planar_2r", work: bool = False) -> Path:
    """The planar 2R with `loops`; its `work` pose (both joints at 30 deg) opens the strut's
    loop, so it is left out unless `work`."""
    data = yaml.safe_load(PLANAR.read_text())
    data["name"] = name
    if not work:
        data["poses_deg"].pop("work")
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump({**data, "loops": loops}, sort_keys=False))
    return path


def test_a_loop_is_read_into_the_model(tmp_path):
    from simkit.model.resolve import resolve

    back = {"name": "strut", "link1": "link_2", "link2": "base_link", "xyz": [-0.3, 0, -0.08]}
    path = _spec(tmp_path, [{**back, "rpy_deg": [0, 0, 0]}])
    spec, _ = load_spec(path)
    robot = resolve(spec, path.read_bytes(), path.name)
    (loop,) = robot.loops
    assert (loop.name, loop.type, loop.link1, loop.link2) == (
        "strut",
        "weld",
        "link_2",
        "base_link",
    )
    assert (loop.xyz, loop.rpy) == ((-0.3, 0, -0.08), (0.0, 0.0, 0.0))


@pytest.mark.parametrize(
    ("change", "field", "why"),
    [
        ({"link2": "link2"}, "loops[0].link2", "unknown link 'link2'; did you mean 'link_2'?"),
        ({"link2": "base_link"}, "loops[0].link2", "not 'base_link' to itself"),
        ({"link1": "link_1"}, "loops[0].link2", "joined by a joint"),
        ({"name": "joint_2"}, "loops[0].name", "already used"),
        ({"name": "strut/1"}, "loops[0].name", "A-Z, a-z, 0-9 and _"),
        ({"type": "hinge"}, "loops[0].type", "'weld'"),
        ({"link_1": "base_link"}, "loops[0].link_1", "unknown field; did you mean 'link1'?"),
    ],
)
def test_the_spec_refuses_a_loop_it_cannot_close_in_one_line(tmp_path, change, field, why):
    path = _spec(tmp_path, [{**STRUT, **change}])
    with pytest.raises(SpecError) as err:
        load_spec(path)
    text = str(err.value)
    assert "\n" not in text and "planar_2r.yaml:" in text and field in text and why in text
    line = int(re.search(r"\.yaml:(\d+):", text).group(1))
    assert (
        path.read_text()
        .splitlines()[line - 1]
        .strip()
        .startswith(("- name", "link", "type", "name"))
    )


def test_a_named_pose_that_opens_the_loop_is_refused(tmp_path):
    path = _spec(tmp_path, [STRUT], work=True)
    with pytest.raises(SpecError, match=r"loops\[0\]\.xyz: pose 'work' puts 'link_2' 0\.1"):
        load_spec(path)
    path = _spec(tmp_path, [{**STRUT, "xyz": [0.3, 0, 0.09]}])
    with pytest.raises(SpecError, match=r"pose 'home' puts 'link_2' 0\.01 m and 0 rad"):
        load_spec(path)


def test_a_floating_base_closes_no_loop_on_the_root(tmp_path):
    path = _spec(tmp_path, [{**STRUT, "link1": "base_footprint", "xyz": [0.3, 0, 0.08]}])
    data = yaml.safe_load(path.read_text())
    data["floating_base"] = True
    data["joints"][0]["type"] = "floating"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    with pytest.raises(SpecError, match=r"loops\[0\]\.link1: a floating base moves freely"):
        load_spec(path)


def test_the_same_pair_closed_twice_is_refused(tmp_path):
    path = _spec(tmp_path, [STRUT, {**STRUT, "name": "strut2"}])
    with pytest.raises(SpecError, match=r"loops\[1\]\.link2: 'base_link' and 'link_2' are closed"):
        load_spec(path)


#: a bar under the forearm (fixed to it) that rests on the base at home only: the forearm
#: welded to the base, the bar touches the base where the loop holds the robot
BRACKET = {
    "name": "bracket",
    "mass": 0.1,
    "solid": [{"shape": "box", "size": [0.3, 0.02, 0.02], "xyz": [-0.15, 0, -0.035]}],
    "collision": "convex",
}


@pytest.fixture(scope="module")
def welded(tmp_path_factory):
    from simkit.pipeline import build

    folder = tmp_path_factory.mktemp("loops")
    path = _spec(folder, [STRUT], "strut_2r")
    data = yaml.safe_load(path.read_text())
    data["links"][0]["collision"] = "convex"  # the base collides in the kit
    data["links"].append(BRACKET)
    bar = {"name": "bracket_joint", "type": "fixed", "parent": "link_2", "child": "bracket"}
    data["joints"].append(bar)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return build(str(path), folder / "kits")


@pytest.mark.slow
def test_every_format_carries_the_loop_and_the_kit_passes(welded):
    from pxr import Usd, UsdPhysics

    assert not [f.line() for f in welded.findings if not f.ok]
    passed = {f.check for f in welded.findings if f.ok}
    assert {"loops.home", "loops.mjcf", "loops.hold", "loops.pairs", "usd.loops"} <= passed
    kit = welded.kit_dir
    mjcf = (kit / "mjcf/strut_2r.xml").read_text()
    assert (
        '<weld name="strut" body1="base_link" body2="link_2" relpose="0.3 0 0.08 1 0 0 0"' in mjcf
    )
    assert '<exclude body1="base_link" body2="link_2" />' in mjcf
    assert '<exclude body1="base_link" body2="bracket" />' in mjcf  # touching at home
    assert "<weld" in (kit / "mjcf/strut_2r_mjx.xml").read_text()
    for file in ("urdf/strut_2r.urdf", "sdf/strut_2r.sdf"):
        assert "loop 'strut' (weld)" in (kit / file).read_text()
    srdf = (kit / "srdf/strut_2r.srdf").read_text()
    assert '<disable_collisions link1="base_link" link2="link_2" reason="Adjacent" />' in srdf
    assert '<disable_collisions link1="base_link" link2="bracket" reason="Default" />' in srdf
    doc = json.loads((kit / "robot.json").read_text())
    assert [lp["name"] for lp in doc["loops"]] == ["strut"]
    assert doc["collision_pairs"]["loop"] == [["base_link", "bracket"]]
    assert "Closed loops" in (kit / "README.md").read_text()
    stage = Usd.Stage.Open(str(kit / layout.usd_payload("strut_2r", "physics.usda")))
    joint = UsdPhysics.FixedJoint(stage.GetPrimAtPath("/strut_2r/joints/strut"))
    assert joint.GetExcludeFromArticulationAttr().Get() is True


def _tampered(welded, tmp_path, mjcf_from: str, mjcf_to: str, json_z: float | None = None) -> Kit:
    """A copy of the kit with the MJCF's weld (and robot.json's loop, with `json_z`) moved."""
    kit = tmp_path / "kit"
    shutil.copytree(welded.kit_dir, kit)
    for name in ("strut_2r.xml", "strut_2r_mjx.xml"):
        path = kit / "mjcf" / name
        text = path.read_text()
        assert mjcf_from in text
        path.write_text(text.replace(mjcf_from, mjcf_to))
    if json_z is not None:
        doc = json.loads((kit / "robot.json").read_text())
        doc["loops"][0]["origin_xyz"][2] = json_z
        (kit / "robot.json").write_text(json.dumps(doc))
    return Kit.open(kit)


@pytest.mark.slow
def test_a_tampered_relpose_fails(welded, tmp_path):
    weld = 'relpose="0.3 0 0.08 1 0 0 0"'
    kit = _tampered(welded, tmp_path / "mjcf", weld, 'relpose="0.3 0 0.085 1 0 0 0"')
    failed = {f.check for f in check_loops(kit) if not f.ok}
    assert failed == {"loops.mjcf"}
    # moved in both files alike: the tree no longer puts link_2 there at home
    kit = _tampered(welded, tmp_path / "both", weld, 'relpose="0.3 0 0.085 1 0 0 0"', 0.085)
    failed = {f.check for f in check_loops(kit) if not f.ok}
    assert "loops.home" in failed


@pytest.mark.slow
def test_a_pair_excluded_around_a_loop_must_touch_at_home(welded, tmp_path):
    kit = tmp_path / "kit"
    shutil.copytree(welded.kit_dir, kit)
    doc = json.loads((kit / "robot.json").read_text())
    doc["collision_pairs"]["loop"].append(["link_1", "bracket"])  # 5 mm apart at home
    (kit / "robot.json").write_text(json.dumps(doc))
    (finding,) = [f for f in check_loops(Kit.open(kit)) if f.check == "loops.pairs"]
    assert not finding.ok and "link_1-bracket: apart at home" in finding.detail


@pytest.mark.slow
def test_a_weld_robot_json_does_not_list_fails(welded, tmp_path):
    kit = tmp_path / "kit"
    shutil.copytree(welded.kit_dir, kit)
    doc = json.loads((kit / "robot.json").read_text())
    del doc["loops"]
    (kit / "robot.json").write_text(json.dumps(doc))
    failed = {f.check: f.detail for f in check_loops(Kit.open(kit)) if not f.ok}
    assert "MJCF welds ['strut'] are not robot.json's loops []" in failed["loops.mjcf"]
    assert "not around a loop" in failed["loops.pairs"]  # its excluded pair too
    from pxr import Usd

    from simkit.check.loops import usd_findings

    stage = Usd.Stage.Open(str(kit / "usd/strut_2r.usda"))
    (finding,) = usd_findings(Kit.open(kit), stage, "/strut_2r")
    assert not finding.ok and "excluded joints ['strut'] are not the loops" in finding.detail
