"""Independent rigid-body dynamics of a robot tree, from the model alone (no MuJoCo).

Recursive Newton-Euler (Luh, Walker and Paul 1980; Craig, "Introduction to Robotics", ch. 6)
in root-frame vectors, and forward dynamics by the unit-vector method (Walker and Orin 1982):
M(q) column k = RNEA(q, 0, e_k) without gravity, h(q, qd) = RNEA(q, qd, 0) with gravity.
Joint axes, origins, masses, CoMs and inertia tensors are read from the `Robot` (the spec's
values after resolve); the kinematics are written out here rather than taken from
`kinematics.py`, so a mistake there cannot hide in both sides of the free-fall comparison.

Joint friction (N m) is Coulomb friction, regularised as f * tanh(qd / FRICTION_SPEED) so the
ODE stays smooth; damping is viscous (N m s/rad); armature (kg m^2) adds to M's diagonal.
Gravity is GRAVITY (m/s^2) along the root frame's -z, as MuJoCo's default.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simkit.model.robot import Robot

GRAVITY = 9.81  # m/s^2, MuJoCo's default |gravity|
#: rad/s: below this speed Coulomb friction fades linearly to zero (tanh regularisation).
FRICTION_SPEED = 1e-3
#: solve_ivp tolerances: global error far below the 1e-3 rad comparison bound.
RTOL, ATOL = 1e-9, 1e-11


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for 3-vectors (numpy's cross is ~100x slower on single vectors)."""
    a0, a1, a2 = a
    b0, b1, b2 = b
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _rot_rpy(rpy) -> np.ndarray:
    """URDF fixed-axis roll-pitch-yaw: Rz(yaw) @ Ry(pitch) @ Rx(roll)."""
    r, p, y = rpy
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    return rz @ ry @ rx


def _rot_axis(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by `angle` about unit `axis`: I + sin K + (1 - cos) K^2."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


@dataclass(frozen=True)
class Tree:
    """The robot as arrays: one body per joint (its child link), in tree order."""

    names: tuple[str, ...]  # movable joint names, the order of q
    parent: tuple[int, ...]  # parent body index, -1 for the root
    kind: tuple[str, ...]  # "revolute", "prismatic" or "fixed"
    dof: tuple[int, ...]  # index into q, -1 for a fixed joint
    origin_rot: tuple[np.ndarray, ...]
    origin_pos: tuple[np.ndarray, ...]
    axis: tuple[np.ndarray, ...]
    mass: np.ndarray
    com: tuple[np.ndarray, ...]
    inertia: tuple[np.ndarray, ...]
    armature: np.ndarray
    damping: np.ndarray
    friction: np.ndarray

    @staticmethod
    def of(robot: Robot) -> Tree:
        index = {j.child: i for i, j in enumerate(robot.joints)}
        movable = [j.name for j in robot.movable_joints]
        parent, kind, dof, rots, poss, axes, mass, com, inertia = [], [], [], [], [], [], [], [], []
        for joint in robot.joints:
            parent.append(index.get(joint.parent, -1))
            kind.append({"continuous": "revolute"}.get(joint.type, joint.type))
            dof.append(movable.index(joint.name) if joint.name in movable else -1)
            rots.append(_rot_rpy(joint.rpy))
            poss.append(np.asarray(joint.xyz, float))
            axes.append(np.asarray(joint.axis, float) / np.linalg.norm(joint.axis))
            inertial = robot.link(joint.child).inertial
            mass.append(inertial.mass if inertial else 0.0)
            com.append(np.asarray(inertial.com if inertial else (0, 0, 0), float))
            if inertial:
                ixx, iyy, izz, ixy, ixz, iyz = inertial.inertia
                inertia.append(np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]))
            else:
                inertia.append(np.zeros((3, 3)))
        joints = {j.name: j for j in robot.joints}
        return Tree(
            names=tuple(movable),
            parent=tuple(parent),
            kind=tuple(kind),
            dof=tuple(dof),
            origin_rot=tuple(rots),
            origin_pos=tuple(poss),
            axis=tuple(axes),
            mass=np.array(mass),
            com=tuple(com),
            inertia=tuple(inertia),
            armature=np.array([joints[n].armature for n in movable]),
            damping=np.array([joints[n].damping for n in movable]),
            friction=np.array([joints[n].friction for n in movable]),
        )

    def poses(self, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """(R_root_body, p_root_body) of every body at q."""
        out: list[tuple[np.ndarray, np.ndarray]] = []
        for i, p in enumerate(self.parent):
            r_p, o_p = out[p] if p >= 0 else (np.eye(3), np.zeros(3))
            rot, pos = r_p @ self.origin_rot[i], o_p + r_p @ self.origin_pos[i]
            if self.kind[i] == "revolute":
                rot = rot @ _rot_axis(self.axis[i], q[self.dof[i]])
            elif self.kind[i] == "prismatic":
                pos = pos + rot @ self.axis[i] * q[self.dof[i]]
            out.append((rot, pos))
        return out

    def rnea(self, q, qd, qdd, gravity: bool, poses=None) -> np.ndarray:
        """Joint forces (N m or N) for motion (q, qd, qdd), with or without gravity."""
        poses = poses if poses is not None else self.poses(q)
        n = len(self.parent)
        omega, alpha, acc = [None] * n, [None] * n, [None] * n  # acc: of the body origin
        force, moment = [np.zeros(3) for _ in range(n)], [np.zeros(3) for _ in range(n)]
        a_root = np.array([0.0, 0.0, GRAVITY if gravity else 0.0])  # gravity as base accel.
        for i, p in enumerate(self.parent):
            rot, pos = poses[i]
            w_p, al_p, a_p, o_p = (
                (omega[p], alpha[p], acc[p], poses[p][1])
                if p >= 0
                else (np.zeros(3), np.zeros(3), a_root, np.zeros(3))
            )
            d = pos - o_p
            a_o = a_p + _cross(al_p, d) + _cross(w_p, _cross(w_p, d))
            w, al = w_p, al_p
            k = self.dof[i]
            if k >= 0:
                axis = rot @ self.axis[i]
                if self.kind[i] == "revolute":
                    w = w_p + axis * qd[k]
                    al = al_p + axis * qdd[k] + _cross(w_p, axis * qd[k])
                else:
                    a_o = a_o + axis * qdd[k] + 2 * _cross(w_p, axis * qd[k])
            omega[i], alpha[i], acc[i] = w, al, a_o
            r = rot @ self.com[i]
            a_c = a_o + _cross(al, r) + _cross(w, _cross(w, r))
            inertia = rot @ self.inertia[i] @ rot.T
            f = self.mass[i] * a_c
            force[i] = f
            moment[i] = inertia @ al + _cross(w, inertia @ w) + _cross(r, f)
        tau = np.zeros(len(self.names))
        for i in range(n - 1, -1, -1):
            p = self.parent[i]
            if p >= 0:
                force[p] = force[p] + force[i]
                moment[p] = moment[p] + moment[i] + _cross(poses[i][1] - poses[p][1], force[i])
            k = self.dof[i]
            if k >= 0:
                axis = poses[i][0] @ self.axis[i]
                tau[k] = axis @ (moment[i] if self.kind[i] == "revolute" else force[i])
        return tau

    def mass_matrix(self, q, poses=None) -> np.ndarray:
        """M(q) including armature (kg m^2): sum over bodies of m Jv^T Jv + Jw^T I Jw, with
        Jw column k = axis_k and Jv column k = axis_k x (c - o_k) for every revolute joint k
        above the body (axis_k for a prismatic one). Same result as the unit-vector method
        (RNEA with qdd = e_k), with far fewer operations."""
        poses = poses if poses is not None else self.poses(q)
        n = len(self.names)
        out = np.diag(self.armature).astype(float)
        axes = [poses[i][0] @ self.axis[i] for i in range(len(self.parent))]
        for b, (rot, pos) in enumerate(poses):
            if self.mass[b] == 0.0 and not self.inertia[b].any():
                continue
            c = pos + rot @ self.com[b]
            jv, jw = np.zeros((3, n)), np.zeros((3, n))
            i = b
            while i >= 0:
                k = self.dof[i]
                if k >= 0:
                    if self.kind[i] == "revolute":
                        jw[:, k] = axes[i]
                        jv[:, k] = _cross(axes[i], c - poses[i][1])
                    else:
                        jv[:, k] = axes[i]
                i = self.parent[i]
            inertia = rot @ self.inertia[b] @ rot.T
            out += self.mass[b] * (jv.T @ jv) + jw.T @ inertia @ jw
        return out

    def acceleration(self, q, qd) -> np.ndarray:
        """qdd from M qdd + h = -damping qd - friction tanh(qd / FRICTION_SPEED)."""
        poses = self.poses(q)
        h = self.rnea(q, qd, np.zeros(len(self.names)), True, poses)
        passive = -self.damping * qd - self.friction * np.tanh(qd / FRICTION_SPEED)
        return np.linalg.solve(self.mass_matrix(q, poses), passive - h)


class EvaluationBudget(RuntimeError):
    """The integration needed more dynamics evaluations than its budget (a stiff setup)."""


def integrate(
    robot: Robot, q0, duration: float, times: np.ndarray, max_evals: int | None = None
) -> np.ndarray:
    """Joint positions at `times` (s) after release from rest at q0: solve_ivp (DOP853,
    rtol RTOL, atol ATOL), raising EvaluationBudget after `max_evals` evaluations of the
    dynamics. Returns shape (len(times), n_dof)."""
    from scipy.integrate import solve_ivp  # lazy: scipy is only needed here

    tree = Tree.of(robot)
    n = len(tree.names)
    evals = [0]

    def rhs(_t, state):
        evals[0] += 1
        if max_evals is not None and evals[0] > max_evals:
            raise EvaluationBudget(f"more than {max_evals} dynamics evaluations")
        q, qd = state[:n], state[n:]
        return np.concatenate([qd, tree.acceleration(q, qd)])

    state0 = np.concatenate([np.asarray(q0, float), np.zeros(n)])
    sol = solve_ivp(
        rhs, (0.0, duration), state0, method="DOP853", t_eval=times, rtol=RTOL, atol=ATOL
    )
    if not sol.success:  # pragma: no cover - DOP853 on a smooth ODE
        raise RuntimeError(f"free-fall integration failed: {sol.message}")
    return sol.y[:n].T
