"""An MJCF `<equality><weld>` between two bodies of the robot closes a kinematic loop (issue
42, class 8): the import carries it as a spec `loops` weld, at the pose the tree gives at
home, by the rule a URDF link with two parents follows (importer/translate/loops.py), and
lists it as closed; a `<connect>` (a ball closure) stays listed as left out."""

from __future__ import annotations

import pytest

from mjcf_models import listed, spec_of, write

LINK = (
    '<inertial pos="0 0 0.1" mass="0.5" diaginertia="2e-3 2e-3 5e-4"/>'
    '<geom type="capsule" fromto="0 0 0 0 0 0.2" size="0.02"/>'
)
#: a two-link arm and a strut beside it, both on the base; the strut's tip welded to the
#: forearm (`tie`), the strut pinned to the upper arm too (`pin`, a connect)
STRUT = f"""<mujoco model="strut">
  <worldbody>
    <body name="base"><inertial pos="0 0 0" mass="2" diaginertia="1e-2 1e-2 1e-2"/>
      <geom type="box" size="0.05 0.05 0.02"/>
      <body name="upper" pos="0 0 0.02"><joint name="shoulder" axis="0 1 0" range="-1 1"/>{LINK}
        <body name="fore" pos="0 0 0.2"><joint name="elbow" axis="0 1 0" range="-1 1"/>{LINK}
        </body>
      </body>
      <body name="strut" pos="0.1 0 0.02"><joint name="strut_j" axis="0 1 0" range="-1 1"/>{LINK}
      </body>
    </body>
  </worldbody>
  <equality>
    <weld name="tie" body1="fore" body2="strut"/>
    <connect name="pin" body1="upper" body2="strut" anchor="0 0 0.1"/>{{more}}
  </equality>
</mujoco>
"""


def test_a_body_weld_becomes_a_loop_and_a_connect_stays_listed(tmp_path):
    spec = spec_of(
        write(tmp_path / "src", STRUT.replace("{more}", ""), "strut.xml"), tmp_path / "o"
    )
    (loop,) = spec["loops"]
    assert (loop["name"], loop["type"], loop["link1"], loop["link2"]) == (
        "tie",
        "weld",
        "fore",
        "strut",
    )
    # at home (all joints 0) the strut's frame is 0.1 m out and 0.2 m below the forearm's
    assert loop["xyz"] == pytest.approx([0.1, 0, -0.2]) and loop["rpy"] == [0, 0, 0]
    said = listed(spec)
    assert "closed by a weld" in said["equality.tie"]
    assert "closed" not in said["equality.pin"]


def test_a_weld_the_tree_holds_already_stays_listed(tmp_path):
    more = '\n    <weld name="twice" body1="upper" body2="fore"/>'
    spec = spec_of(
        write(tmp_path / "src", STRUT.replace("{more}", more), "strut.xml"), tmp_path / "o"
    )
    assert [lp["name"] for lp in spec["loops"]] == ["tie"]
    assert "joined by a joint already" in listed(spec)["equality.twice"]


@pytest.mark.slow
def test_the_welded_strut_builds_a_checked_kit_and_the_source_check_compares_it(tmp_path):
    import json

    from simkit.check.kit import Kit
    from simkit.check.source import check_source
    from simkit.pipeline import build

    write(tmp_path / "src", STRUT.replace("{more}", ""), "strut.xml")
    spec_of(tmp_path / "src" / "strut.xml", tmp_path / "o")
    result = build(str(tmp_path / "o" / "strut.yaml"), tmp_path / "kits")  # CheckFailed if not
    passed = {f.check for f in result.findings if f.ok}
    assert {"source.loops", "loops.mjcf", "loops.hold", "usd.loops"} <= passed
    doc = json.loads((result.kit_dir / "robot.json").read_text())
    doc["loops"][0]["link1"] = "upper"  # tampered: no weld of the source joins upper
    (result.kit_dir / "robot.json").write_text(json.dumps(doc))
    kit = Kit.open(result.kit_dir, tmp_path / "o" / "strut.source.xml")
    (finding,) = [f for f in check_source(kit) if f.check == "source.loops"]
    assert not finding.ok and "no body weld of the source" in finding.detail
