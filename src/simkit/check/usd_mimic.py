"""Mimic joints as the USD writes them, read from the MJCF's joint equalities (an independent
path: the MJCF couples a follower to its leader by `<equality><joint>`). A revolute follower is
coupled by PhysxMimicJointAPI alone, with no drive; PhysX does not enforce a linear mimic, so a
prismatic follower is driven by its leader's servo instead (docs/usd.md, "Mimic joints")."""

from __future__ import annotations

import mujoco


def followers(mj) -> dict[int, tuple[int, float]]:
    """{follower joint: (leader joint, offset)} of the MJCF's joint equalities. The USD couples
    a hinge follower by PhysxMimicJointAPI alone (no drive, not even its passive damping);
    PhysX does not enforce a linear mimic, so a slide follower is driven by its leader's servo,
    aimed at the offset (m) (docs/usd.md)."""
    out = {}
    for e in range(mj.neq):
        follower, leader = int(mj.eq_obj1id[e]), int(mj.eq_obj2id[e])
        if mj.eq_type[e] == mujoco.mjtEq.mjEQ_JOINT and leader >= 0:
            out[follower] = (leader, float(mj.eq_data[e, 0]))
    return out


def follower_servo(mj, jid: int, follows: dict, actuated: dict) -> tuple[int, float] | None:
    """(leader's actuator, offset m) of a slide follower without a servo of its own."""
    if jid in actuated or jid not in follows:
        return None
    if mj.jnt_type[jid] != mujoco.mjtJoint.mjJNT_SLIDE or follows[jid][0] not in actuated:
        return None
    return actuated[follows[jid][0]], follows[jid][1]
