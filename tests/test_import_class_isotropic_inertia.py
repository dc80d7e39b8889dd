"""Issue 42, class 3: a fingertip whose inertia is nearly isotropic (two principal moments
agree to five digits) and whose principal axes are turned 0.1 rad from its link frame. The
products of inertia in the link frame are then below 1e-12 kg m^2, and the kit's writer
(kitio/fmt.num) writes them as 0. `source.links` compares the full tensors in the link
frame with a tolerance scaled to the tensor's norm plus that floor: the kit passes, and a
real change of a moment still fails."""

from __future__ import annotations

import hashlib
import json
import math

import numpy as np
import pytest

from mjcf_models import write
from simkit.check.kit import Kit
from simkit.check.source import check_source
from simkit.kitio.fmt import vec

MOMENTS = (4.55823e-07, 4.55814e-07, 4.49559e-07)  # kg m^2, principal
TURN = 0.1  # rad about z: principal axes against the link frame


def _hand(tip_inertial: str) -> str:
    """A palm and one two-joint finger whose tip carries `tip_inertial`."""
    return f"""<mujoco model="hand">
  <worldbody>
    <body name="palm" pos="0 0 0.2">
      <inertial pos="0 0 0" mass="0.3" diaginertia="0.0003 0.0002 0.0001"/>
      <geom type="box" size="0.04 0.04 0.01"/>
      <body name="finger" pos="0.03 0 0.01">
        <joint name="f1" axis="0 1 0" range="-1 1"/>
        <inertial pos="0 0 0.02" mass="0.02" diaginertia="2e-06 2e-06 1e-06"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.04" size="0.008"/>
        <body name="tip" pos="0 0 0.045">
          <joint name="f2" axis="0 1 0" range="-1 1"/>
          {tip_inertial}
          <geom type="sphere" size="0.009" pos="0 0 0.01"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator><position joint="f1" kp="1"/><position joint="f2" kp="1"/></actuator>
</mujoco>
"""


SOURCE = _hand(
    f'<inertial pos="0 0 0.01" quat="{math.cos(TURN / 2)} 0 0 {math.sin(TURN / 2)}" '
    f'mass="0.01" diaginertia="{vec(MOMENTS)}"/>'
)


def _as_written(moments=MOMENTS) -> str:
    """The tip's inertial as the kit's writer gives it: the link-frame tensor, each term
    through kitio/fmt (terms below 1e-12 kg m^2 written as 0)."""
    c, s = math.cos(TURN), math.sin(TURN)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    t = rot @ np.diag(moments) @ rot.T
    full = (t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2])
    return f'<inertial pos="0 0 0.01" mass="0.01" fullinertia="{vec(full)}"/>'


def _kit(tmp_path, kit_text: str) -> Kit:
    """A kit folder holding what the source check reads: robot.json and its MJCF."""
    source = write(tmp_path / "src", SOURCE, "hand.xml")
    folder = tmp_path / "kit"
    write(folder, kit_text, "hand.xml")
    doc = {
        "files": {"mjcf": "hand.xml"},
        "source": {"file": "hand.xml", "sha256": hashlib.sha256(source.read_bytes()).hexdigest()},
    }
    (folder / "robot.json").write_text(json.dumps(doc))
    return Kit(folder, source)


def _links(kit: Kit):
    return next(f for f in check_source(kit) if f.check == "source.links")


def test_the_products_written_as_zero_are_below_the_floor():
    assert 'fullinertia="' in _as_written() and " 0 0 0" in _as_written()


def test_a_nearly_isotropic_turned_tip_passes(tmp_path):
    finding = _links(_kit(tmp_path, _hand(_as_written())))
    assert finding.ok, finding.line()


def test_a_real_inertia_change_still_fails(tmp_path):
    changed = (MOMENTS[0], MOMENTS[1], MOMENTS[2] * 1.01)  # one moment 1 % off
    finding = _links(_kit(tmp_path, _hand(_as_written(changed))))
    assert not finding.ok
    assert "link 'tip': inertia" in finding.line()


@pytest.mark.slow
def test_the_imported_hand_builds(tmp_path):
    from simkit.importer import import_robot
    from simkit.pipeline import build

    source = write(tmp_path / "src", SOURCE, "hand.xml")
    spec = import_robot(source, tmp_path / "spec").spec_path
    kit = build(str(spec), tmp_path / "kits").kit_dir
    assert (kit / "robot.json").is_file()
