"""The check stage: read a written kit the way a user would and compare everything.

`run_checks` is what `simkit build` runs on its staging folder and `simkit check` on any kit.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from simkit.check.findings import Finding
from simkit.check.freefall_check import check_freefall
from simkit.check.geometry_check import check_collision, check_glb
from simkit.check.kit import Kit
from simkit.check.legged_check import check_legged
from simkit.check.motion_check import check_motion
from simkit.check.mujoco_check import check_hold, check_models
from simkit.check.published import check_published
from simkit.check.ros_check import check_ros
from simkit.check.urdf_check import check_urdf
from simkit.check.usd_check import check_usd

Check = Callable[[Kit], list[Finding]]

CHECKS: dict[str, Check] = {
    "published": check_published,
    "models": check_models,
    "urdf": check_urdf,
    "collision": check_collision,
    "glb": check_glb,
    "ros": check_ros,
    "hold": check_hold,
    "legged": check_legged,
    "usd": check_usd,
    "motion": check_motion,
    "freefall": check_freefall,
}


def run_checks(kit_dir: Path, checks: dict[str, Check] | None = None) -> list[Finding]:
    """Every finding for the kit at `kit_dir`, in a stable order."""
    kit = Kit.open(kit_dir)
    findings: list[Finding] = []
    for check in (checks or CHECKS).values():
        findings.extend(check(kit))
    return findings
