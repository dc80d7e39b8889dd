"""Small shims over MuJoCo API differences between 3.1 and 4.x (the kits support both)."""

from __future__ import annotations

import mujoco
import numpy as np


def full_mass_matrix(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Dense joint-space inertia matrix M(q) (kg m^2), after mj_forward."""
    full = np.zeros((model.nv, model.nv))
    if hasattr(data, "qM"):  # MuJoCo 3.x: mj_fullM(m, dst, qM)
        mujoco.mj_fullM(model, full, data.qM)
    else:  # MuJoCo 4.x: mj_fullM(m, d, dst)
        mujoco.mj_fullM(model, data, full)
    return full
