"""One shared comparison: a reader's tool pose vs robot.json's FK at seeded configurations."""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from simkit.check.findings import Finding, compare
from simkit.check.kit import Kit

Pose = Callable[[np.ndarray], np.ndarray]


def fk_agrees(
    kit: Kit, check: str, reader: str, tool_pose: Pose, configs: Iterable[np.ndarray], tol: float
) -> list[Finding]:
    """`check` (position, m) and `check.rotation` (matrix entries): `tool_pose(q)`, the tool
    frame in the kit's base frame as `reader` computes it, vs `Kit.fk(q)` from robot.json's
    joints, at every configuration of `configs` (rad or m, robot.json joint order)."""
    tool = kit.doc.get("tool_frame")
    pos, rot = [], []
    for q in configs:
        actual, expected = tool_pose(q), kit.fk(q)
        pos.append(actual[:3, 3] - expected[:3, 3])
        rot.append(actual[:3, :3] - expected[:3, :3])
    label = f"at {len(pos)} random configurations, {reader} vs robot.json FK"
    return [
        compare(check, f"{tool} {label}", np.zeros((len(pos), 3)), pos, tol, "m"),
        compare(
            f"{check}.rotation",
            f"{tool} rotation {label}",
            np.zeros((len(rot), 3, 3)),
            rot,
            tol,
            "",
        ),
    ]
