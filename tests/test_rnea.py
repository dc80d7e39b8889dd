"""rnea.py, the independent dynamics behind the free-fall validation: its mass matrix and bias
forces equal MuJoCo's on the written MJCF, for a world-mounted 2R arm and a 6R arm."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from simkit.model import rnea
from simkit.pipeline import model_from_spec


@pytest.mark.parametrize("name", ["ecn_2r", "rosie_1000"])
def test_mass_matrix_and_bias_match_mujoco(name, kit_factory):
    kit = kit_factory(name)
    robot = model_from_spec(name)
    tree = rnea.Tree.of(robot)
    model = mujoco.MjModel.from_xml_path(str(kit.kit_dir / "mjcf" / f"{name}.xml"))
    data = mujoco.MjData(model)
    qpos = [model.joint(n).qposadr[0] for n in tree.names]
    dofs = [model.joint(n).dofadr[0] for n in tree.names]
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, qd = rng.uniform(-1.5, 1.5, len(qpos)), rng.uniform(-2, 2, len(qpos))
        data.qpos[qpos], data.qvel[dofs] = q, qd
        mujoco.mj_forward(model, data)
        full = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, full)
        mass = full[np.ix_(dofs, dofs)]
        assert np.allclose(tree.mass_matrix(q), mass, rtol=1e-8, atol=1e-9)
        bias = tree.rnea(q, qd, np.zeros(len(q)), gravity=True)
        assert np.allclose(bias, data.qfrc_bias[dofs], rtol=1e-7, atol=1e-7)
        # unit-vector method (RNEA with qdd = e_k) gives the same M as the Jacobian sum
        columns = [tree.rnea(q, 0 * q, np.eye(len(q))[k], gravity=False) for k in range(len(q))]
        assert np.allclose(np.column_stack(columns) + np.diag(tree.armature), mass, atol=1e-9)


def test_free_pendulum_conserves_energy():
    """Without friction, a released arm keeps its energy (integrator sanity)."""
    from dataclasses import replace

    robot = model_from_spec("ecn_2r")
    robot = replace(robot, joints=tuple(replace(j, friction=0.0) for j in robot.joints))
    tree = rnea.Tree.of(robot)
    q0 = np.radians([-60.0, 30.0])
    times = np.linspace(0.0, 1.0, 11)
    traj = rnea.integrate(robot, q0, 1.0, times)
    assert not np.allclose(traj[-1], q0, atol=0.05)  # it moved

    def potential(q):
        poses = tree.poses(q)
        return -sum(
            tree.mass[i] * rnea.GRAVITY * (pos + rot @ tree.com[i])[2] * -1
            for i, (rot, pos) in enumerate(poses)
        )

    # at the turning points of a released double pendulum energy is all potential: a
    # coarse proxy is that potential never exceeds its starting value
    assert max(potential(q) for q in traj) <= potential(q0) + 1e-6
