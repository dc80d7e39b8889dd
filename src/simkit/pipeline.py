"""The pipeline, the one place that knows the stage order: spec (load + validate) -> model
(resolve) -> derive -> emit -> write to staging -> simulate (on the staged files) -> emit the
report files -> check -> publish (swap kit and zip into place).

A build writes into a staging folder beside the output, checks it there, then swaps it into
place (kitio/atomic.py); a failure at any step leaves the previous kit and zip untouched, and
a build whose files equal the published ones writes nothing there. Each build is recorded for
the no-op rebuild (kitio/noop.py), which the CLI tries before importing this module.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

from simkit.check import published_numbers, run_checks_cached
from simkit.check.findings import Finding, failure_message
from simkit.derive import derive_all
from simkit.emit import EMITTERS, emit_all, emit_reports, usd
from simkit.emit.ros2 import package_warning
from simkit.errors import CheckFailed, SimkitError, SpecError, UnknownRobot
from simkit.kitio import atomic, confine, forked, layout, manifest, noop, reuse, room
from simkit.kitio.archive import zip_bytes
from simkit.kitio.cache import (
    Arrays,
    Cache,
    cached_stage,
    code_digest,
    decode_json,
    digest,
    encode_json,
    make_key,
)
from simkit.kitio.resources import data_dir, robot_names
from simkit.model.resolve import resolve
from simkit.model.robot import Robot
from simkit.simulate import simulate_all
from simkit.spec import locate as spec_locate
from simkit.spec.load import load_yaml
from simkit.spec.validate import load_spec

Progress = Callable[[str], None]


@dataclass(frozen=True)
class BuildResult:
    """What a build wrote and what its checks found."""

    robot: str
    kit_dir: Path
    zip_path: Path
    files: dict[str, bytes]
    findings: list[Finding] = field(default_factory=list)
    #: one-line warnings about the spec (e.g. package.xml's maintainer left to the default)
    warnings: tuple[str, ...] = ()
    #: False when the published kit and zip already held these bytes (nothing was written)
    changed: bool = True


def find_spec(target: str) -> tuple[Path, str]:
    """A robot name from robots/ or a path to a YAML file -> (path, name shown in messages).
    Outputs name the spec by `spec_identity` instead, which is the same however it is given."""
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


def spec_identity(path: Path) -> str:
    """The spec as every output names it: its file name (`NAME.yaml`). Never its folder, the
    working directory or how the build named it (a robot name, a relative or absolute path),
    so every way of naming one spec gives the same bytes (issue 38)."""
    return path.name


def model_from_spec(
    target: str,
    progress: Progress | None = None,
    cache: Cache | None = None,
    jobs: int | None = None,
    before_derive: Callable[[str], None] | None = None,
) -> Robot:
    """Load, validate, resolve and derive: the frozen model every emitter reads. `cache`:
    see `derive.derive_all` (None: the user cache folder); `jobs`: worker processes;
    `before_derive`: called with the robot's name once the spec is valid (the build's
    fail-fast checks of `--out`)."""
    path, shown = find_spec(target)
    say = progress or (lambda _msg: None)
    say(f"spec {shown}")
    spec, doc = load_spec(path, display=str(path) if not shown.startswith("robots/") else shown)
    robot = resolve(spec, doc.text.encode("utf-8"), spec_identity(path))
    if before_derive is not None:
        before_derive(robot.name)
    say("derive solids, mass properties, servos")
    try:
        return derive_all(robot, path.parent, cache, jobs, progress)
    except SpecError as exc:  # raised deep in a step: give it the spec's FILE:LINE
        raise spec_locate.locate(exc, doc, spec, path.parent) from None
    except spec_locate.LIBRARY_ERRORS as exc:
        raise spec_locate.refusal(exc, doc) from exc


def unstaged(exc: SimkitError, staging: Path | str, out_dir: Path | str) -> SimkitError:
    """`exc` naming the kit's place under the build's output folder instead of the staging
    folder the user never sees (`.NAME.XXXX.staging/NAME_description/step/NAME.step` is
    `OUT/NAME_description/step/NAME.step`); a located SpecError is kept as it is."""
    text = str(exc)
    if str(staging) not in text or type(exc) not in (SimkitError, CheckFailed):
        return exc
    return type(exc)(text.replace(str(staging), str(out_dir)))


def _located(target: str, exc: SpecError) -> SpecError:
    """A SpecError from a stage after derive, with the spec's FILE:LINE where it can be found."""
    path, shown = find_spec(target)
    spec, doc = load_spec(path, display=str(path) if not shown.startswith("robots/") else shown)
    return spec_locate.locate(exc, doc, spec, path.parent)


def _explainer(target: str) -> Callable[[Finding], str | None]:
    """Words a failed `published.*` finding at its line of the spec (check/published_numbers)."""
    path, shown = find_spec(target)
    doc = load_yaml(path, display=str(path) if not shown.startswith("robots/") else shown)
    return lambda finding: published_numbers.explain(finding, doc)


#: Libraries whose versions appear in, or shape, the emitted bytes (part of the emit key).
EMIT_LIBRARIES = (
    "numpy",
    "manifold3d",
    "trimesh",
    "coacd",
    "mujoco",
    "usd-core",
    "jinja2",
    "cadquery-ocp",
    "cadquery-ocp-novtk",
)
#: Libraries the simulate stage's figures depend on.
SIMULATE_LIBRARIES = ("numpy", "scipy", "mujoco", "matplotlib")


def _pack_files(files: dict[str, bytes]) -> Arrays:
    """Files as one byte blob plus a JSON index (no pickle), for a cache entry."""
    import numpy as np

    index, offset = [], 0
    for path, data in files.items():
        index.append([path, offset, offset + len(data)])
        offset += len(data)
    blob = np.frombuffer(b"".join(files.values()), dtype=np.uint8)
    return {"index": encode_json(index), "blob": blob}


def _unpack_files(stored: Arrays) -> dict[str, bytes]:
    """The files of an entry; a stored path that would leave the kit raises (a miss)."""
    blob = stored["blob"].tobytes()
    files = {path: blob[start:end] for path, start, end in decode_json(stored["index"])}
    confine.check_tree(files)
    return files


def _template_bytes() -> list[bytes]:
    templates = data_dir("templates")
    return [
        part
        for path in sorted(templates.rglob("*"))
        if path.is_file()
        for part in (path.relative_to(templates).as_posix().encode(), path.read_bytes())
    ]


def _emitters(usd_format: str, step: bool) -> dict:
    """The model emitters for these options (`step`: False drops `step/NAME.step`)."""
    emitters = {**EMITTERS, "usd": usd.emitter(usd_format)}
    if not step:
        del emitters["step"]
    return emitters


def emit_cached(robot: Robot, usd_format: str, cache: Cache, step: bool = True) -> dict[str, bytes]:
    """The emit stage, reusing the files of an earlier build of an identical model. Emitters
    are pure functions of the model and the templates, so a hit runs no emitter (a warm
    rebuild does not even import pxr)."""
    return cached_stage(
        cache,
        "emit",
        [digest(robot).encode(), *_template_bytes()],
        lambda: emit_all(robot, _emitters(usd_format, step)),
        _pack_files,
        _unpack_files,
        EMIT_LIBRARIES,
        {"usd_format": usd_format, "step": step},
    )


def simulate_cached(
    kit_dir: Path, robot: Robot, cache: Cache, step: bool = True, kit_files: Iterable[str] = ()
) -> dict[str, bytes]:
    """The simulate stage on the staged kit, then the report emitters. The staged files are
    a pure function of the model and the options, so the model's digest, the templates and
    the staged paths (`kit_files`, whose formats robot.json lists) key both."""
    names = sorted(kit_files)
    return cached_stage(
        cache,
        "simulate",
        [digest(robot).encode(), *_template_bytes(), "\n".join(names).encode()],
        lambda: emit_reports(robot, simulate_all(kit_dir, robot), step=step, kit_files=names),
        _pack_files,
        _unpack_files,
        (*EMIT_LIBRARIES, *SIMULATE_LIBRARIES),
        {"step": step},
    )


def _zip_cached(files: dict[str, bytes], top: str, cache: Cache) -> bytes:
    """`zip_bytes`, reused when the same files were zipped before: deflate at level 9 is most
    of a warm rebuild of a robot with large CAD meshes (seconds per 10 MB)."""
    import numpy as np

    return cached_stage(
        cache,
        "zip",
        [item for path in sorted(files) for item in (path.encode(), files[path])],
        lambda: zip_bytes(files, top),
        lambda data: {"zip": np.frombuffer(data, dtype=np.uint8)},
        lambda stored: stored["zip"].tobytes(),
        params={"top": top},
    )


def write_tree(root: Path, files: dict[str, bytes], old_root: Path | None = None) -> None:
    """Write `files` (POSIX relative paths) under `root`, each confined to it; files equal
    to those under `old_root` are hard links to them (they keep their mtime: kitio/reuse.py)."""
    reuse.write_tree(root, files, old_root)


def build(
    target: str,
    out_dir: Path,
    check: bool = True,
    progress: Progress | None = None,
    cache: Cache | None = None,
    jobs: int | None = None,
    usd_format: str = "usda",
    step: bool = True,
    remember: bool = True,
) -> BuildResult:
    """Build one kit into `out_dir/NAME_description` and `out_dir/NAME-sim-kit.zip`;
    `usd_format`: "usda" (text) or "usdc" (binary) for `usd/NAME.*`; `step`: False leaves
    out `step/NAME.step` (and the Open CASCADE import it costs); `remember`: record the
    build for the no-op rebuild (kitio/noop.py; off for a throw-away `out_dir`).

    A build of a spec this code has not built before starts a warm worker at once, which
    imports Open CASCADE while the model is derived and then writes and checks the STEP
    (kitio/forked.py); a rebuild does not, as its STEP comes from the cache."""
    cache = Cache.at() if cache is None else cache
    hint = _rebuild_hint(target, cache, usd_format, step)
    cold = step and (hint is None or cache.get("built", hint) is None)
    with forked.warm_worker(("OCP",) if cold else ()):
        result, named = _build(target, out_dir, check, progress, cache, jobs, usd_format, step)
    if hint is not None and cold and cache.enabled:
        import numpy as np

        cache.put("built", hint, {"built": np.ones(1, dtype=np.uint8)})
    if remember and cache.enabled and not cache.readonly and cache.root is not None:
        passed = sum(f.ok for f in result.findings)
        counts = (passed, len(result.findings)) if check else None
        options = noop.options(usd_format, step, check)
        noop.remember(cache.root, target, out_dir, options, result.robot, named, counts)
    return result


def _named_files(robot: Robot, target: str) -> list[Path]:
    """The files the spec names (mesh files), which the no-op record watches."""
    base = find_spec(target)[0].parent
    shapes = [s for link in robot.links for s in (*link.shapes, *link.collision_shapes)]
    return [base / s.file for s in shapes if s.file]


def _rebuild_hint(target: str, cache: Cache, usd_format: str, step: bool) -> str | None:
    """Cache key of "this spec file was built by this code with these options" (a hint
    only: a mesh file the spec uses may have changed), or None without a readable spec."""
    try:
        data = find_spec(target)[0].read_bytes()
    except (OSError, UnknownRobot):
        return None
    params = {"usd_format": usd_format, "step": step}
    return make_key("built", 1, [code_digest().encode(), data], params, ())


def _build(
    target: str,
    out_dir: Path,
    check: bool,
    progress: Progress | None,
    cache: Cache,
    jobs: int | None,
    usd_format: str,
    step: bool,
) -> tuple[BuildResult, list[Path]]:
    """`build` after the warm worker is settled: the result and the files the spec names."""
    say = progress or (lambda _msg: None)
    # an --out that cannot take the kit is one line before any derive work (kitio/room.py)
    robot = model_from_spec(target, progress, cache, jobs, partial(room.preflight, out_dir))
    step = step and robot.step  # the spec can leave the STEP out too
    say("emit")
    files = emit_cached(robot, usd_format, cache, step)
    kit_name = layout.kit_dir_name(robot.name)
    lock = atomic.acquire(out_dir)  # one build at a time into out_dir
    try:
        said = atomic.repair(out_dir, robot.name)  # what a killed build left
        if said:
            print(f"simkit: warning: {said}", file=sys.stderr)
        with atomic.staging_area(out_dir, robot.name) as staging:
            try:
                files, findings, changed = _stage_and_publish(
                    target, robot, files, staging, out_dir, check, say, cache, step
                )
            except SimkitError as exc:  # a check that refused to read the staged kit
                raise unstaged(exc, staging, out_dir) from None
    finally:
        atomic.release(lock)
    warning = package_warning(robot)
    result = BuildResult(
        robot.name,
        out_dir / kit_name,
        out_dir / layout.zip_name(robot.name),
        files,
        findings,
        warnings=(warning,) if warning else (),
        changed=changed,
    )
    return result, _named_files(robot, target)


def publish_files(
    out_dir: Path, robot: str, files: dict[str, bytes], zip_data: bytes
) -> tuple[Path, Path, bool]:
    """Publish a kit built and checked elsewhere (a Ray worker) into `out_dir` exactly as a
    local build publishes its own: under the output folder's lock, staged beside it with
    unchanged files reused, and one atomic commit. Returns (kit folder, zip path, whether
    anything changed)."""
    lock = atomic.acquire(out_dir)
    try:
        said = atomic.repair(out_dir, robot)
        if said:
            print(f"simkit: warning: {said}", file=sys.stderr)
        with atomic.staging_area(out_dir, robot) as staging:
            atomic.stage_kit(staging, out_dir, robot, files)
            atomic.stage_file(staging, out_dir, layout.zip_name(robot), zip_data)
            record = manifest.make(robot, files, zip_data)
            atomic.stage_file(staging, out_dir, manifest.name(robot), record)
            changed = atomic.commit(staging, out_dir, robot)
    finally:
        atomic.release(lock)
    return out_dir / layout.kit_dir_name(robot), out_dir / layout.zip_name(robot), changed


def _stage_and_publish(
    target: str,
    robot: Robot,
    files: dict[str, bytes],
    staging: Path,
    out_dir: Path,
    check: bool,
    say: Progress,
    cache: Cache,
    step: bool,
) -> tuple[dict[str, bytes], list[Finding], bool]:
    """Write the kit and zip into `staging`, simulate, check, and publish them (with the
    lock held): (all files, findings, whether anything was published)."""
    kit_name = layout.kit_dir_name(robot.name)
    staged_kit = staging / kit_name
    atomic.stage_kit(staging, out_dir, robot.name, files)
    say("simulate")
    try:
        reports = simulate_cached(staged_kit, robot, cache, step, files)
    except SpecError as exc:  # e.g. freefall.pose: a release that leaves the limits
        raise _located(target, exc) from None
    clash = sorted(set(files) & set(reports))
    if clash:
        raise RuntimeError(f"a model emitter and a report emitter both write {clash[0]}")
    atomic.stage_kit(staging, out_dir, robot.name, reports)
    files = dict(sorted({**files, **reports}.items()))
    zip_data = _zip_cached(files, kit_name, cache)
    atomic.stage_file(staging, out_dir, layout.zip_name(robot.name), zip_data)
    atomic.stage_file(
        staging, out_dir, manifest.name(robot.name), manifest.make(robot.name, files, zip_data)
    )
    findings: list[Finding] = []
    if check:
        say("check")
        source = None if robot.source is None else find_spec(target)[0].parent / robot.source[0]
        findings = run_checks_cached(staged_kit, files, cache, source)
        failed = [f for f in findings if not f.ok]
        if failed:
            raise CheckFailed(failure_message(robot.name, failed, _explainer(target)))
    changed = atomic.commit(staging, out_dir, robot.name)  # kit and zip as one unit
    return files, findings, changed
