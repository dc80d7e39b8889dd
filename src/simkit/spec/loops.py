"""The optional `loops:` section of a spec: kinematic loops closed by a constraint.

A kit's joints form a tree. A mechanism whose links meet twice (an end effector fixed both
to the arm and to the world, a four-bar) keeps its tree and closes each loop here: link
`link2` is held at `xyz`/`rpy` (m, rad; or `rpy_deg`) in `link1`'s frame, the pose it has at
`home`. `type: weld` holds all six degrees of freedom (MuJoCo `<equality><weld>`, a USD
FixedJoint excluded from the articulation); the field leaves room for `connect` (a ball
closure, position only) to follow.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterator
from typing import Literal

from pydantic import BaseModel, ConfigDict, model_validator

# Own base types (not imported from schema.py, which imports this module).
Vec3 = tuple[float, float, float]
Problem = tuple[tuple, str]

#: closure types a spec may name: a weld holds position and orientation
TYPES = ("weld",)


class LoopSpec(BaseModel):
    """One loop closure: `link2`'s frame held at `xyz`/`rpy` in `link1`'s frame (its pose at
    the spec's home). `link1` may be the root frame (the world)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    name: str
    type: Literal["weld"] = "weld"
    link1: str
    link2: str
    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 | None = None
    rpy_deg: Vec3 | None = None

    @model_validator(mode="after")
    def _one_rpy(self) -> LoopSpec:
        if self.rpy is not None and self.rpy_deg is not None:
            raise ValueError("give rpy or rpy_deg, not both")
        return self

    def rpy_rad(self) -> Vec3:
        """Orientation in radians."""
        if self.rpy_deg is not None:
            return tuple(math.radians(a) for a in self.rpy_deg)  # type: ignore[return-value]
        return self.rpy or (0.0, 0.0, 0.0)


def _unknown(name: str, known: set[str]) -> str:
    """`unknown link 'X'`, with the closest known name when one is close."""
    close = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.6)
    return f"unknown link '{name}'" + (f"; did you mean '{close[0]}'?" if close else "")


def problems(spec) -> Iterator[Problem]:
    """Each loop names two different known links (or the root) not joined directly by a
    joint (a joint holds them already), a name no joint or other loop has, and each pair
    once."""
    known = {link.name for link in spec.links} | {spec.root}
    jointed = {frozenset((j.parent, j.child)) for j in spec.joints}
    names = {j.name for j in spec.joints}
    pairs: set[frozenset] = set()
    for i, loop in enumerate(spec.loops):
        if loop.name in names:
            yield ("loops", i, "name"), f"name '{loop.name}' is already used by a joint or loop"
        names.add(loop.name)
        bad = [(f, n) for f, n in (("link1", loop.link1), ("link2", loop.link2)) if n not in known]
        for field, name in bad:
            yield ("loops", i, field), _unknown(name, known)
        pair = frozenset((loop.link1, loop.link2))
        if bad:
            continue
        if loop.link1 == loop.link2:
            yield ("loops", i, "link2"), f"a loop joins two links, not '{loop.link1}' to itself"
        elif pair in jointed:
            why = f"'{loop.link1}' and '{loop.link2}' are joined by a joint: no loop to close"
            yield ("loops", i, "link2"), why
        elif pair in pairs:
            yield ("loops", i, "link2"), f"'{loop.link1}' and '{loop.link2}' are closed twice"
        pairs.add(pair)
