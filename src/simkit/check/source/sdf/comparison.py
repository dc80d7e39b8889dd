"""The source plant against the kit plant, both read by Drake (plant.py): `Compare` gives the
findings on joint types and limits (rad or m), every body's mass (kg), CoM (m) and inertia
(kg m^2) in the kit's link frame, and every body's and kit frame's pose at SEEDS seeded
configurations (FK_TOL m, and in rotation). Kept apart from the package's `__init__.py`,
which lays the source's files out and reads them, so each module holds one topic.
"""

from __future__ import annotations

import numpy as np

from simkit.check.findings import Finding
from simkit.check.source.sdf.plant import Plant
from simkit.check.source.shared import (
    ABS_LENGTH,
    REL,
    Allowed,
    inertia_close,
    unlisted_findings,
    vector_text,
)
from simkit.kitio.oneline import one_line

FK_TOL = 1e-6
SEEDS = 100
#: Drake joint types the kit carries as several revolute joints: their name suffixes
#: (translate/ball_joints.py; importer/formats/sdf/universal.py)
SPLIT = {"ball_rpy": ("_x", "_y", ""), "universal": ("_1", "")}


class Compare:
    """The source plant against the kit plant (`findings`)."""

    def __init__(self, source: Plant, kit: Plant, allowed: Allowed) -> None:
        self.s, self.k, self.allowed = source, kit, allowed

    def kit_body(self, name: str):
        return self.k.bodies.get(self.allowed.links.get(one_line(name), name))

    def kit_joint(self, name: str):
        """The kit's joint of source joint `name`; Drake files a joint under its child's
        model, so a joint of the top model to a nested link is also tried by its own name."""
        found = self.k.joints.get(self.allowed.joints.get(one_line(name), name))
        if found is None and "::" in name:
            return self.kit_joint(name.rpartition("::")[2])
        return found

    def listed(self, key: str) -> bool:
        return key in self.allowed.keys

    def findings(self) -> list[Finding]:
        out = unlisted_findings(
            "source.joints", self.joints(), f"{len(self.s.joints)} joints: types and limits agree"
        )
        out += unlisted_findings(
            "source.links",
            self.links(),
            f"{len(self.s.bodies)} bodies: masses, CoMs and inertias agree",
        )
        return out + unlisted_findings(
            "source.fk", self.fk(), f"every body's pose agrees at {SEEDS} seeded configurations"
        )

    def joints(self) -> list[str]:
        out = []
        for name, joint in sorted(self.s.joints.items()):
            kind = joint.type_name()
            if kind == "quaternion_floating" or self.listed(f"joints.{name}"):
                continue
            if kind in SPLIT:
                parts = [self.kit_joint(f"{name}{x}") for x in SPLIT[kind]]
                if any(p is None or p.type_name() != "revolute" for p in parts):
                    said = " and ".join(name + x for x in SPLIT[kind])
                    out.append(
                        f"joint '{name}': a {kind}, not the revolute joints {said} in the kit"
                    )
                continue  # Drake reads no limits of either (a universal's: Drake 1.51)
            other = self.kit_joint(name)
            if other is None:
                if kind != "weld":  # a weld may be merged away (a fixed joint's link kept)
                    out.append(f"joint '{name}' is missing from the kit")
                continue
            if other.type_name() != kind and not self.listed(f"joints.{name}.type"):
                out.append(f"joint '{name}': {kind} in the source, {other.type_name()} in the kit")
                continue
            if kind in ("revolute", "prismatic"):
                out += self._limits(name, joint, other)
        return out

    def _limits(self, name: str, joint, other) -> list[str]:
        out = []
        for attr, a, b in (
            ("lower", joint.position_lower_limits()[0], other.position_lower_limits()[0]),
            ("upper", joint.position_upper_limits()[0], other.position_upper_limits()[0]),
        ):
            if self.listed(f"joints.{name}.{attr}") or (np.isinf(a) and np.isinf(b)):
                continue
            if not np.isfinite(a) or not np.isfinite(b) or abs(a - b) > REL * abs(a) + ABS_LENGTH:
                out.append(f"joint '{name}': {attr} {a:.9g} in the source, {b:.9g} in the kit")
        return out

    def links(self) -> list[str]:
        out = []
        for name, body in sorted(self.s.bodies.items()):
            other = self.kit_body(name)
            if other is None:
                if not self.listed(f"links.{name}") and body.default_mass() > 0:
                    out.append(f"link '{name}' is missing from the kit")
                continue
            m0, c0, i0 = _mass(body, self.s.kit_frame(body))
            m1, c1, i1 = _mass(other, np.eye(4))
            key = f"links.{name}"
            if abs(m0 - m1) > REL * m0 and not self.listed(f"{key}.mass"):
                out.append(f"link '{name}': mass {m0:.9g} kg in the source, {m1:.9g} in the kit")
            if m0 == 0:
                continue
            if np.max(np.abs(c0 - c1)) > REL * np.max(np.abs(c0)) + ABS_LENGTH and not self.listed(
                f"{key}.com"
            ):
                out.append(
                    f"link '{name}': CoM {vector_text(c0)}"
                    f" m in the source, {vector_text(c1)} in the kit"
                )
            if not inertia_close(i0, i1) and not self.listed(f"{key}.inertia"):
                out.append(
                    f"link '{name}': inertia {vector_text(np.diag(i0))} kg m^2 in the source, "
                    f"{vector_text(np.diag(i1))} in the kit"
                )
        return out

    def fk(self) -> list[str]:
        world = self.s.plant.world_body().index()
        mounted = any(
            j.parent_body().index() == world and j.type_name() != "quaternion_floating"
            for j in self.s.joints.values()
        )
        roots = [b for b in self.s.bodies.values() if self.s.inboard(b) is None]
        ref = None if mounted or not roots else roots[0]
        ref_kit = None if ref is None else self.kit_body(self._name(ref))
        if ref is not None and ref_kit is None:
            return [f"the root body '{ref.name()}' is missing from the kit"]
        pairs = [(n, b, self.kit_body(n)) for n, b in sorted(self.s.bodies.items())]
        pairs = [(n, b, k) for n, b, k in pairs if k is not None]
        frames = [(n, f, self.kit_body(n)) for n, f in sorted(self.s.frames.items())]
        frames = [(n, f, k) for n, f, k in frames if k is not None and n not in self.s.bodies]
        rng = np.random.default_rng(0)
        worst: dict[str, float] = {}
        for _ in range(SEEDS):
            self._configure(rng)
            xs0 = np.eye(4) if ref is None else self.s.pose(ref)
            xk0 = np.eye(4) if ref_kit is None else self.k.pose(ref_kit)
            poses = [(n, self.s.pose(b) @ self.s.kit_frame(b), k) for n, b, k in pairs]
            poses += [(n, self.s.frame_pose(f), k) for n, f, k in frames]  # kit frames
            for name, pose, other in poses:
                xs = np.linalg.inv(xs0) @ pose
                xk = np.linalg.inv(xk0) @ self.k.pose(other)
                err = float(np.max(np.abs(xs[:3] - xk[:3])))
                if err > FK_TOL:
                    worst[name] = max(worst.get(name, 0.0), err)
        return [
            f"link '{n}': pose off by up to {e:.3g} m (or rotation) at seeded configurations"
            for n, e in worst.items()
        ]

    def _name(self, body) -> str:
        return next(n for n, b in self.s.bodies.items() if b.index() == body.index())

    def _configure(self, rng) -> None:
        """One seeded configuration, set in both plants: each revolute or prismatic joint
        in its source range (else +-pi rad, +-0.1 m), a ball as three angles x, y, z."""
        from pydrake.math import RollPitchYaw, RotationMatrix

        for name, joint in sorted(self.s.joints.items()):
            kind = joint.type_name()
            if kind == "ball_rpy":
                angles = rng.uniform(-np.pi, np.pi, 3)
                rot = RotationMatrix.MakeXRotation(angles[0])
                rot = rot.multiply(RotationMatrix.MakeYRotation(angles[1]))
                rot = rot.multiply(RotationMatrix.MakeZRotation(angles[2]))
                joint.set_angles(self.s.context, RollPitchYaw(rot).vector())
                for suffix, angle in zip(("_x", "_y", ""), angles, strict=True):
                    other = self.kit_joint(name + suffix)
                    if other is not None and other.num_positions() == 1:
                        other.set_angle(self.k.context, angle)
            elif kind == "universal":
                angles = [self._draw(joint, k, rng) for k in range(2)]
                joint.set_angles(self.s.context, angles)
                for suffix, angle in zip(SPLIT[kind], angles, strict=True):
                    other = self.kit_joint(name + suffix)
                    if other is not None and other.num_positions() == 1:
                        other.set_angle(self.k.context, angle)
            elif kind in ("revolute", "prismatic"):
                value = self._draw(joint, 0, rng)
                _set(joint, self.s.context, value)
                other = self.kit_joint(name)
                if other is not None and other.num_positions() == 1:
                    _set(other, self.k.context, value)

    @staticmethod
    def _draw(joint, k: int, rng) -> float:
        """A value of the joint's `k`th position in its range (else +-pi rad, +-0.1 m)."""
        span = 0.1 if joint.type_name() == "prismatic" else np.pi
        low, high = joint.position_lower_limits()[k], joint.position_upper_limits()[k]
        return rng.uniform(low if np.isfinite(low) else -span, high if np.isfinite(high) else span)


def _set(joint, context, value: float) -> None:
    """A revolute (rad) or prismatic (m) joint's position."""
    if joint.type_name() == "revolute":
        joint.set_angle(context, value)
    elif joint.type_name() == "prismatic":
        joint.set_translation(context, value)


def _mass(body, x_bk: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """(kg, CoM m, inertia about the CoM kg m^2) in the kit frame K (`x_bk`: K in B)."""
    spatial = body.default_spatial_inertia()
    mass = float(spatial.get_mass())
    com = np.asarray(spatial.get_com())
    about_origin = spatial.CalcRotationalInertia().CopyToFullMatrix3()
    about_com = about_origin - mass * (float(com @ com) * np.eye(3) - np.outer(com, com))
    rot = x_bk[:3, :3].T
    return mass, rot @ (com - x_bk[:3, 3]), rot @ about_com @ rot.T
