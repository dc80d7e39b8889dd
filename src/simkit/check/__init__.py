"""The check stage: read a written kit the way a user would and compare everything.

`run_checks` is what `simkit build` runs on its staging folder and `simkit check` on any kit.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict
from functools import partial
from pathlib import Path

from simkit.check.findings import Finding, require
from simkit.check.freefall import check_freefall
from simkit.check.generated import check_generated
from simkit.check.geometry import check_collision, check_glb
from simkit.check.kit import Kit
from simkit.check.legged import check_legged
from simkit.check.motion import check_motion
from simkit.check.mujoco import check_hold, check_models, check_parameters
from simkit.check.published_numbers import check_published
from simkit.check.ros import check_ros
from simkit.check.self_collision import check_self_collision
from simkit.check.step import check_step
from simkit.check.urdf import check_urdf
from simkit.check.usd import check_usd
from simkit.kitio.cache import Cache, cached_stage, decode_json, encode_json
from simkit.kitio.forked import run_all

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
    "self_collision": check_self_collision,
    "step": check_step,
    "generated": check_generated,
}


def run_checks(kit_dir: Path, checks: dict[str, Check] | None = None) -> list[Finding]:
    """Every finding for the kit at `kit_dir`, in a stable order."""
    kit = Kit.open(kit_dir)
    checks = checks or CHECKS
    jobs = {name: partial(_guarded, name, check, kit) for name, check in checks.items()}
    found = run_all(jobs, BACKGROUND)
    return [finding for name in checks for finding in found[name]]


#: Checks run in a forked child beside the others (kitio/forked.py): the STEP check's Open
#: CASCADE import and re-read would otherwise add to a cold build's time.
BACKGROUND = ("step",)


def _guarded(name: str, check: Check, kit: Kit) -> list[Finding]:
    """The check's findings; an exception (a damaged kit: a missing or unreadable file)
    becomes one failed finding, not a traceback."""
    try:
        return check(kit)
    except Exception as exc:
        why = " ".join(f"{type(exc).__name__}: {exc}".split())
        return [require(f"{name}.error", False, f"the {name} check cannot run: {why}")]


#: Libraries whose behaviour the findings depend on (part of the cache key).
CHECK_LIBRARIES = (
    "numpy",
    "scipy",
    "mujoco",
    "yourdfpy",
    "trimesh",
    "usd-core",
    "manifold3d",
    "cadquery-ocp",
)


def run_checks_cached(kit_dir: Path, files: dict[str, bytes], cache: Cache) -> list[Finding]:
    """`run_checks`, reusing the findings of an earlier build whose kit was byte-identical.

    Checks are a pure function of the kit's bytes, simkit's code and the libraries that read
    them, so those make the content-addressed key. Only passing results are stored;
    `simkit check` never uses the cache.
    """
    return cached_stage(
        cache,
        "checks",
        [part for path in sorted(files) for part in (path.encode("utf-8"), files[path])],
        lambda: run_checks(kit_dir),
        lambda found: (
            {"findings": encode_json([asdict(f) for f in found])}
            if all(f.ok for f in found)
            else None
        ),
        lambda stored: [Finding(**item) for item in decode_json(stored["findings"])],  # type: ignore[union-attr]
        CHECK_LIBRARIES,
    )
