"""A passive biped (issue 42, class 4): a free base on closed-loop legs (an equality
constraint) with springs, which cannot stand on a kit's position servos at home, is built
instead of refused. The spec, robot.json and the README say it needs active balance; the
legged check keeps the passive drop and replaces the stand with a suspended hold (the base
held in place for the check only), which still fails servos that cannot hold home."""

from __future__ import annotations

import json
import shutil

import pytest
import yaml

from simkit.check.kit import Kit
from simkit.check.legged import check_legged
from simkit.importer import import_robot

LEG = """
      <body name="{side}_thigh" pos="0 {y} -0.1">
        <joint name="{side}_hip" axis="0 1 0" range="-1 1" stiffness="20"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.35" size="0.03" mass="1"/>
        <body name="{side}_shank" pos="0 0 -0.35">
          <joint name="{side}_knee" axis="0 1 0" range="-1.5 0" stiffness="20"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.35" size="0.025" mass="0.6"/>
          <body name="{side}_foot" pos="0 0 -0.35">
            <geom type="sphere" size="0.03" mass="0.1"/></body>
        </body>
      </body>
      <body name="{side}_strut" pos="0.05 {y} -0.1">
        <joint name="{side}_strut_hinge" axis="0 1 0" range="-1 1"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.01" mass="0.2"/>
      </body>"""

#: a torso on two point-footed legs, each closed by a strut (connect equality), sprung joints
BIPED = f"""<mujoco model="biped">
  <worldbody>
    <body name="torso" pos="0 0 0.9"><freejoint/>
      <geom type="box" size="0.1 0.15 0.1" mass="8"/>{LEG.format(side="left", y=0.1)}{
    LEG.format(side="right", y=-0.1)
}
    </body>
  </worldbody>
  <equality>
    <connect body1="left_strut" body2="left_shank" anchor="0 0 -0.3"/>
    <connect body1="right_strut" body2="right_shank" anchor="0 0 -0.3"/>
  </equality>
</mujoco>
"""


def _imported(tmp_path):
    (tmp_path / "biped.xml").write_text(BIPED)
    return import_robot(tmp_path / "biped.xml", tmp_path / "out")


def test_the_biped_is_imported_and_marked(tmp_path):
    done = _imported(tmp_path)
    spec = yaml.safe_load(done.spec_path.read_text())
    assert spec["floating_base"] and spec["needs_active_balance"].startswith(
        "on the kit's position servos at home its base sinks"
    )
    said = [line for line in done.lines if "needs active balance" in line]
    assert len(said) == 1 and said[0].startswith("biped.xml:3: freejoint: changed:")


@pytest.mark.slow
def test_the_biped_builds_with_a_suspended_hold(tmp_path):
    from simkit.pipeline import build

    done = _imported(tmp_path)
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    checks = {f.check for f in result.findings}
    assert {"legged.drop.floor", "legged.hold.home", "legged.hold.finite"} <= checks
    assert not any(c.startswith("legged.stand") for c in checks)
    doc = json.loads((result.kit_dir / "robot.json").read_text())
    assert "sinks" in doc["floating_base"]["needs_active_balance"]
    assert "needs active balance" in (result.kit_dir / "README.md").read_text()

    # the stand it replaces fails this robot: without the mark, the base sinks
    plain = tmp_path / "plain"
    shutil.copytree(result.kit_dir, plain)
    doc["floating_base"].pop("needs_active_balance")
    (plain / "robot.json").write_text(json.dumps(doc))
    stand = {f.check: f.ok for f in check_legged(Kit(plain))}
    assert stand["legged.stand.height"] is False

    # the hold still fails servos that cannot hold home: a spring stronger than the hip's
    weak = tmp_path / "weak"
    shutil.copytree(result.kit_dir, weak)
    mjcf = weak / "mjcf" / "biped.xml"
    text = mjcf.read_text().replace(
        '<joint name="left_hip" ', '<joint name="left_hip" stiffness="1000" springref="1" '
    )
    mjcf.write_text(text)
    held = {f.check: f.ok for f in check_legged(Kit(weak))}
    assert held["legged.hold.home"] is False and held["legged.drop.floor"] is True
