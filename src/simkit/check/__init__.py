"""The check stage: read a written kit the way a user would and compare everything.

`run_checks` is what `simkit build` runs on its staging folder and `simkit check` on any kit.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from simkit.check.findings import Finding, require
from simkit.check.freefall_check import check_freefall
from simkit.check.generated_check import check_generated
from simkit.check.geometry_check import check_collision, check_glb
from simkit.check.kit import Kit
from simkit.check.legged_check import check_legged
from simkit.check.motion_check import check_motion
from simkit.check.mujoco_check import check_hold, check_models, check_parameters
from simkit.check.published import check_published
from simkit.check.ros_check import check_ros
from simkit.check.urdf_check import check_urdf
from simkit.check.usd_check import check_usd

Check = Callable[[Kit], list[Finding]]

CHECKS: dict[str, Check] = {
    "published": check_published,
    "models": check_models,
    "mjcf_parameters": check_parameters,
    "urdf": check_urdf,
    "collision": check_collision,
    "glb": check_glb,
    "ros": check_ros,
    "hold": check_hold,
    "legged": check_legged,
    "usd": check_usd,
    "motion": check_motion,
    "freefall": check_freefall,
    "generated": check_generated,
}


def run_checks(kit_dir: Path, checks: dict[str, Check] | None = None) -> list[Finding]:
    """Every finding for the kit at `kit_dir`, in a stable order."""
    kit = Kit.open(kit_dir)
    findings: list[Finding] = []
    for name, check in (checks or CHECKS).items():
        try:
            findings.extend(check(kit))
        except Exception as exc:  # a damaged kit (missing or unreadable file): fail, no traceback
            why = " ".join(f"{type(exc).__name__}: {exc}".split())
            findings.append(require(f"{name}.error", False, f"the {name} check cannot run: {why}"))
    return findings


#: Libraries whose behaviour the findings depend on (part of the cache key).
CHECK_LIBRARIES = ("numpy", "scipy", "mujoco", "yourdfpy", "trimesh", "usd-core", "manifold3d")


def run_checks_cached(kit_dir: Path, files: dict[str, bytes], cache) -> list[Finding]:
    """`run_checks`, reusing the findings of an earlier build whose kit was byte-identical.

    Checks are a pure function of the kit's bytes, simkit's code and the libraries that read
    them, so those make the content-addressed key (issue 3: a warm rebuild re-runs no slow
    pure step). Only passing results are stored; `simkit check` never uses the cache.
    """
    from dataclasses import asdict

    from simkit.cache import code_digest, decode_json, encode_json, make_key

    inputs = [part for path in sorted(files) for part in (path.encode("utf-8"), files[path])]
    key = make_key("checks", 1, inputs, {"code": code_digest()}, CHECK_LIBRARIES)
    stored = cache.get("checks", key)
    if stored is not None:
        return [Finding(**item) for item in decode_json(stored["findings"])]
    findings = run_checks(kit_dir)
    if all(f.ok for f in findings):
        cache.put("checks", key, {"findings": encode_json([asdict(f) for f in findings])})
    return findings
