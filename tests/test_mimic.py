"""A mimic joint's MJCF equality holds a loaded follower to its leader (emit/mjcf.py's
MIMIC_* settings): MuJoCo's default softness let a parallel gripper's mimic fingers sag 0.7 deg."""

from __future__ import annotations

import mujoco
import numpy as np

from simkit.emit.mjcf import MIMIC_SOLIMP, MIMIC_TIMECONST_STEPS
from simkit.kitio.fmt import vec

TIMESTEP = 0.002


def _follower_sag(equality_attrs: str) -> float:
    """Degrees a 50 g follower finger, 0.1 m long and horizontal, sags from its mimic after
    2 s while a servo holds its leader at 0."""
    xml = f"""<mujoco><option timestep="{TIMESTEP}"/><worldbody><body name="leader">
      <joint name="lead" axis="0 1 0" armature="0.001"/>
      <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01" mass="0.05"/>
      <body name="follower" pos="0 0.05 0"><joint name="follow" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01" mass="0.05"/></body></body>
      </worldbody><equality><joint joint1="follow" joint2="lead" polycoef="0 -1 0 0 0"
      {equality_attrs}/></equality>
      <actuator><position joint="lead" kp="100" forcerange="-10 10"/></actuator></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    for _ in range(round(2.0 / TIMESTEP)):
        mujoco.mj_step(model, data)
    lead, follow = data.qpos
    return float(np.degrees(abs(follow + lead)))


def test_kit_mimic_equality_holds_a_loaded_follower():
    solref = vec((MIMIC_TIMECONST_STEPS * TIMESTEP, 1.0))
    kit = _follower_sag(f'solref="{solref}" solimp="{vec(MIMIC_SOLIMP)}"')
    default = _follower_sag("")
    assert default > 0.1  # the failure this fixes: MuJoCo's default equality is soft
    assert kit < 0.02 < default / 10
