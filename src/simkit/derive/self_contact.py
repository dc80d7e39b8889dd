"""Self-contact depth of a robot's collision geometry at a joint configuration (derive step).

The IK reference cases must be collision-free (issue 12): their seeds and expected solutions
are drawn again where links would meet, and a listed solution that collides is flagged with its
depth. This works on the model in memory, before any file is written: the same collision
geometry the kit's MJCF gets (collision_pairs.collision_model_xml) with MuJoCo's rule for the
kit, adjacent links excluded. The written kit is checked again by check/self_collision_check.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from simkit.derive.collision_pairs import adjacent_pairs, collision_model_xml
from simkit.model.kinematics import excluded_pairs
from simkit.model.robot import Robot


def depth_function(robot: Robot, joints: Sequence[str]) -> Callable[[Sequence[float]], float]:
    """f(q) -> deepest penetration (m, 0 when free) between non-adjacent links, q the values
    of `joints` (rad or m), every other joint at 0."""
    import mujoco

    # as the kit's MJCF excludes them
    skip = sorted(set(adjacent_pairs(robot)) | set(excluded_pairs(robot)))
    model = mujoco.MjModel.from_xml_string(collision_model_xml(robot, skip))
    data = mujoco.MjData(model)
    adr = [int(model.jnt_qposadr[model.joint(name).id]) for name in joints]

    def depth(q: Sequence[float]) -> float:
        for a, value in zip(adr, q, strict=True):
            data.qpos[a] = value
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        return max([0.0, *(-float(d) for d in data.contact.dist[: data.ncon])])

    return depth
