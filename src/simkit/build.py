"""The pipeline: load+validate -> resolve -> derive -> emit -> write (staging) -> check -> publish.

A build writes into a staging folder beside the output, checks it there, then swaps it into
place; a failure at any step leaves the previous kit and zip untouched.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from simkit import atomic, layout, spec_locate
from simkit.archive import zip_bytes
from simkit.cache import Cache
from simkit.check import run_checks_cached
from simkit.check.findings import Finding
from simkit.derive import derive_all
from simkit.emit import EMITTERS, emit_all, usd
from simkit.errors import CheckFailed, SpecError, UnknownRobot
from simkit.model import Robot
from simkit.resolve import resolve
from simkit.resources import data_dir, robot_names
from simkit.validate import load_spec

Progress = Callable[[str], None]


@dataclass(frozen=True)
class BuildResult:
    """What a build wrote and what its checks found."""

    robot: str
    kit_dir: Path
    zip_path: Path
    files: dict[str, bytes]
    findings: list[Finding] = field(default_factory=list)


def find_spec(target: str) -> tuple[Path, str]:
    """A robot name from robots/ or a path to a YAML file -> (path, name shown in outputs)."""
    candidate = Path(target)
    if candidate.suffix in (".yaml", ".yml"):
        if not candidate.is_file():
            raise UnknownRobot(f"{target}: no such spec file")
        return candidate, candidate.name
    path = data_dir("robots") / f"{target}.yaml"
    if not path.is_file():
        known = ", ".join(robot_names())
        raise UnknownRobot(f"unknown robot '{target}' (known: {known}; or give a path to a .yaml)")
    return path, f"robots/{path.name}"


def model_from_spec(
    target: str,
    progress: Progress | None = None,
    cache: Cache | None = None,
    jobs: int | None = None,
) -> Robot:
    """Load, validate, resolve and derive: the frozen model every emitter reads. `cache`:
    see `derive.derive_all` (None: the user cache folder); `jobs`: worker processes."""
    path, shown = find_spec(target)
    say = progress or (lambda _msg: None)
    say(f"spec {shown}")
    spec, doc = load_spec(path, display=str(path) if not shown.startswith("robots/") else shown)
    robot = resolve(spec, doc.text.encode("utf-8"), shown)
    say("derive solids, mass properties, servos")
    try:
        return derive_all(robot, path.parent, cache, jobs, progress)
    except SpecError as exc:  # raised deep in a step: give it the spec's FILE:LINE
        raise spec_locate.locate(exc, doc, spec, path.parent) from None
    except spec_locate.LIBRARY_ERRORS as exc:
        raise spec_locate.refusal(exc, doc) from exc


#: Libraries whose versions appear in, or shape, the emitted bytes (part of the emit key).
EMIT_LIBRARIES = ("numpy", "manifold3d", "trimesh", "coacd", "mujoco", "usd-core", "jinja2")


def _emit_cached(robot: Robot, usd_format: str, cache: Cache) -> dict[str, bytes]:
    """`emit_all`, reusing the files of an earlier build of an identical model.

    Emitters are pure functions of the model and the templates (no clock, no randomness), so
    the key is the model's content digest, simkit's source digest, every template's bytes,
    the library versions and the options. On
    a hit no emitter runs, so a warm rebuild does not even import pxr. Stored as one byte
    blob plus a JSON index (no pickle), through the cache's digest-checked entries.
    """
    import numpy as np

    from simkit.cache import code_digest, decode_json, digest, encode_json, make_key

    templates = data_dir("templates")
    template_bytes = [
        part
        for path in sorted(templates.rglob("*"))
        if path.is_file()
        for part in (path.relative_to(templates).as_posix().encode(), path.read_bytes())
    ]
    key = make_key(
        "emit",
        1,
        [digest(robot).encode(), code_digest().encode(), *template_bytes],
        {"usd_format": usd_format},
        EMIT_LIBRARIES,
    )
    stored = cache.get("emit", key)
    if stored is not None:
        blob = stored["blob"].tobytes()
        return {path: blob[start:end] for path, start, end in decode_json(stored["index"])}
    files = emit_all(robot, {**EMITTERS, "usd": usd.emitter(usd_format)})
    index, offset = [], 0
    for path, data in files.items():
        index.append([path, offset, offset + len(data)])
        offset += len(data)
    blob = np.frombuffer(b"".join(files.values()), dtype=np.uint8)
    cache.put("emit", key, {"index": encode_json(index), "blob": blob})
    return files


def write_tree(root: Path, files: dict[str, bytes]) -> None:
    """Write `files` (POSIX relative paths) under `root`."""
    for rel, data in files.items():
        target = root.joinpath(*rel.split("/"))
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)


def _swap_in(staged: Path, final: Path) -> None:
    """Replace `final` with `staged`, keeping the old one until the new one is in place."""
    old = final.with_name(f".{final.name}.old")
    if old.exists():
        shutil.rmtree(old) if old.is_dir() else old.unlink()
    if final.exists():
        os.replace(final, old)
    os.replace(staged, final)
    if old.exists():
        shutil.rmtree(old) if old.is_dir() else old.unlink()


def build(
    target: str,
    out_dir: Path,
    check: bool = True,
    progress: Progress | None = None,
    cache: Cache | None = None,
    jobs: int | None = None,
    usd_format: str = "usda",
) -> BuildResult:
    """Build one kit into `out_dir/NAME_description` and `out_dir/NAME-sim-kit.zip`;
    `usd_format`: "usda" (text) or "usdc" (binary) for `usd/NAME.*`."""
    say = progress or (lambda _msg: None)
    cache = Cache.at() if cache is None else cache
    robot = model_from_spec(target, progress, cache, jobs)
    say("emit")
    files = _emit_cached(robot, usd_format, cache)
    kit_name = layout.kit_dir_name(robot.name)
    lock = atomic.acquire(out_dir, robot.name)  # one build at a time into out_dir
    staging = atomic.staging(out_dir, robot.name)
    try:
        staged_kit = staging / kit_name
        write_tree(staged_kit, files)
        staged_zip = staging / layout.zip_name(robot.name)
        staged_zip.write_bytes(zip_bytes(files, kit_name))
        findings: list[Finding] = []
        if check:
            say("check")
            findings = run_checks_cached(staged_kit, files, cache)
            failed = [f for f in findings if not f.ok]
            if failed:
                lines = "; ".join(f.line() for f in failed[:3])
                more = f" (and {len(failed) - 3} more)" if len(failed) > 3 else ""
                raise CheckFailed(f"{robot.name}: {len(failed)} check(s) failed: {lines}{more}")
        atomic.commit(staging, out_dir, robot.name)  # kit and zip as one unit (atomic.py)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
        atomic.release(lock)
    return BuildResult(
        robot.name, out_dir / kit_name, out_dir / layout.zip_name(robot.name), files, findings
    )
