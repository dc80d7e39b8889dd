"""The check stage: read a written kit the way a user would and compare everything.

`run_checks` is what `simkit build` runs on its staging folder and `simkit check` on any kit.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import asdict
from functools import partial
from pathlib import Path

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.kitio.cache import Cache, cached_stage, decode_json, encode_json
from simkit.kitio.forked import run_all

Check = Callable[[Kit], list[Finding]]

#: name -> "module:function" under simkit.check, imported when a check runs: a warm rebuild
#: takes every finding from the cache and need not import MuJoCo, USD or yourdfpy readers
#: (0.7 s of a mobile manipulator's 2.1 s warm rebuild)
_REGISTRY: dict[str, str] = {
    "published": "published_numbers:check_published",
    "models": "mujoco:check_models",
    "mjcf_parameters": "mujoco:check_parameters",
    "gpu_scene": "gpu_scene:check_gpu_scene",
    "urdf": "urdf:check_urdf",
    "collision": "geometry:check_collision",
    "glb": "geometry:check_glb",
    "connected": "connected:check_connected",
    "ros": "ros:check_ros",
    "hold": "mujoco:check_hold",
    "legged": "legged:check_legged",
    "loops": "loops:check_loops",
    "usd": "usd:check_usd",
    "motion": "motion:check_motion",
    "freefall": "freefall:check_freefall",
    "self_collision": "self_collision:check_self_collision",
    "step": "step:check_step",
    "generated": "generated:check_generated",
    "references": "references:check_references",
    "sdf": "sdf:check_sdf",
    "source": "source:check_source",
    "training": "training:check_training",
}


def _load(reference: str) -> Check:
    import importlib

    module, function = reference.split(":")
    return getattr(importlib.import_module(f"simkit.check.{module}"), function)


class _Checks(Mapping[str, Check]):
    """The check registry, in its fixed order: each check imported on first use."""

    def __init__(self) -> None:
        self._loaded: dict[str, Check] = {}

    def __getitem__(self, name: str) -> Check:
        if name not in self._loaded:
            self._loaded[name] = _load(_REGISTRY[name])
        return self._loaded[name]

    def __iter__(self) -> Iterator[str]:
        return iter(_REGISTRY)

    def __len__(self) -> int:
        return len(_REGISTRY)


CHECKS: Mapping[str, Check] = _Checks()


def run_checks(
    kit_dir: Path, checks: Mapping[str, Check] | None = None, source: Path | None = None
) -> list[Finding]:
    """Every finding for the kit at `kit_dir`, in a stable order; `source`: the URDF it was
    imported from, for the source comparison (check/source)."""
    kit = Kit.open(kit_dir, source)
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
    "cadquery-ocp-novtk",
    "drake",  # the SDFormat source proof (check/source/sdf/)
)


def run_checks_cached(
    kit_dir: Path, files: dict[str, bytes], cache: Cache, source: Path | None = None
) -> list[Finding]:
    """`run_checks`, reusing the findings of an earlier build whose kit was byte-identical.

    Checks are a pure function of the kit's bytes, simkit's code and the libraries that read
    them, so those make the content-addressed key (with the `source` file's bytes, which the
    source comparison reads). Only passing results are stored; `simkit check` never uses
    the cache.
    """
    parts = [part for path in sorted(files) for part in (path.encode("utf-8"), files[path])]
    if source is not None:
        parts += [b"source", source.read_bytes()]
    return cached_stage(
        cache,
        "checks",
        parts,
        lambda: run_checks(kit_dir, source=source),
        lambda found: (
            {"findings": encode_json([asdict(f) for f in found])}
            if all(f.ok for f in found)
            else None
        ),
        lambda stored: [Finding(**item) for item in decode_json(stored["findings"])],  # type: ignore[union-attr]
        CHECK_LIBRARIES,
    )
