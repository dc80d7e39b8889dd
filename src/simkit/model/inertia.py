"""Mass properties: the link solid at uniform density, scaled to the spec's mass.

Uses the divergence-theorem volume integrals (Eberly, "Polyhedral Mass Properties", 2002),
so no mesh library is needed on the hot path.
"""

from __future__ import annotations

import numpy as np

from simkit.model.robot import Inertial, Mesh

#: Off-diagonal inertia below this fraction of the largest moment is round-off: the link axes
#: are then the principal axes (keeps symmetric links free of arbitrary eigenvector choices).
DIAGONAL_TOLERANCE = 1e-9


def volume_integrals(mesh: Mesh) -> tuple[float, np.ndarray, np.ndarray]:
    """Volume (m^3), centroid (m) and inertia tensor about the centroid per unit density."""
    tri = mesh.vertices[mesh.faces]
    v0, v1, v2 = tri[:, 0], tri[:, 1], tri[:, 2]
    cross = np.cross(v1 - v0, v2 - v0)
    f1 = v0 + v1 + v2
    f2 = v0 * v0 + v1 * (v0 + v1) + v2 * f1
    f3 = v0 * v0 * v0 + v1 * (v0 * v0 + v0 * v1 + v1 * v1) + v2 * f2
    g0 = f2 + v0 * (f1 + v0)
    g1 = f2 + v1 * (f1 + v1)
    g2 = f2 + v2 * (f1 + v2)
    x, y, z = 0, 1, 2
    integ = np.zeros(10)
    integ[0] = np.sum(cross[:, x] * f1[:, x])
    integ[1] = np.sum(cross[:, x] * f2[:, x])
    integ[2] = np.sum(cross[:, y] * f2[:, y])
    integ[3] = np.sum(cross[:, z] * f2[:, z])
    integ[4] = np.sum(cross[:, x] * f3[:, x])
    integ[5] = np.sum(cross[:, y] * f3[:, y])
    integ[6] = np.sum(cross[:, z] * f3[:, z])
    integ[7] = np.sum(
        cross[:, x] * (v0[:, y] * g0[:, x] + v1[:, y] * g1[:, x] + v2[:, y] * g2[:, x])
    )
    integ[8] = np.sum(
        cross[:, y] * (v0[:, z] * g0[:, y] + v1[:, z] * g1[:, y] + v2[:, z] * g2[:, y])
    )
    integ[9] = np.sum(
        cross[:, z] * (v0[:, x] * g0[:, z] + v1[:, x] * g1[:, z] + v2[:, x] * g2[:, z])
    )
    integ *= np.array(
        [1 / 6, 1 / 24, 1 / 24, 1 / 24, 1 / 60, 1 / 60, 1 / 60, 1 / 120, 1 / 120, 1 / 120]
    )
    volume = integ[0]
    if volume <= 0:
        raise ValueError("mesh has no positive volume (open or inside-out)")
    com = integ[1:4] / volume
    ixx = integ[5] + integ[6] - volume * (com[1] ** 2 + com[2] ** 2)
    iyy = integ[4] + integ[6] - volume * (com[2] ** 2 + com[0] ** 2)
    izz = integ[4] + integ[5] - volume * (com[0] ** 2 + com[1] ** 2)
    ixy = -(integ[7] - volume * com[0] * com[1])
    iyz = -(integ[8] - volume * com[1] * com[2])
    ixz = -(integ[9] - volume * com[2] * com[0])
    tensor = np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])
    return float(volume), com, tensor


def from_solid(mesh: Mesh, mass: float) -> Inertial:
    """Inertial of `mesh` at the uniform density that gives it `mass` (kg)."""
    volume, com, tensor = volume_integrals(mesh)
    scaled = tensor * (mass / volume)
    return Inertial(
        mass=mass,
        com=tuple(float(c) for c in com),  # type: ignore[arg-type]
        inertia=(
            float(scaled[0, 0]),
            float(scaled[1, 1]),
            float(scaled[2, 2]),
            float(scaled[0, 1]),
            float(scaled[0, 2]),
            float(scaled[1, 2]),
        ),
    )


def principal_axes(tensor: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(diagonal inertia, R) with tensor = R diag R^T, R a proper rotation with a fixed sign
    convention, so the same tensor always gives the same quaternion."""
    diag = np.diag(tensor)
    off = tensor - np.diag(diag)
    if np.max(np.abs(off)) <= DIAGONAL_TOLERANCE * max(float(np.max(np.abs(diag))), 1e-300):
        return diag.copy(), np.eye(3)
    values, vectors = np.linalg.eigh(tensor)
    for col in range(3):
        if vectors[np.argmax(np.abs(vectors[:, col])), col] < 0:
            vectors[:, col] = -vectors[:, col]
    if np.linalg.det(vectors) < 0:
        vectors[:, 2] = -vectors[:, 2]
    return values, vectors
