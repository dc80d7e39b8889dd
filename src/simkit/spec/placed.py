"""The spec's base models: `Strict` (frozen, no unknown keys, finite floats) and `Placed`
(a pose in a parent frame). Their own module so that schema.py and the section modules it
imports (loops.py) share one definition without an import cycle."""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, model_validator

Vec3 = tuple[float, float, float]


class Strict(BaseModel):
    """Base: frozen, no unknown keys, finite floats only."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class Placed(Strict):
    """A pose given as translation (m) and roll-pitch-yaw, in radians or degrees."""

    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 | None = None
    rpy_deg: Vec3 | None = None

    @model_validator(mode="after")
    def _one_rpy(self) -> Placed:
        if self.rpy is not None and self.rpy_deg is not None:
            raise ValueError("give rpy or rpy_deg, not both")
        return self

    def rpy_rad(self) -> Vec3:
        """Orientation in radians."""
        if self.rpy_deg is not None:
            return tuple(math.radians(a) for a in self.rpy_deg)  # type: ignore[return-value]
        return self.rpy or (0.0, 0.0, 0.0)
