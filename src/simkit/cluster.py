"""Many robots on a Ray cluster (issue 26): one Ray task per robot, published by the caller.

`simkit build SPEC... --ray` and `simkit publish --ray` send each robot to any Ray worker as
one task. The task carries the spec's bytes and every file the spec names (meshes, kept
blocks), so a worker needs no shared disk. The worker builds and checks the kit in a private
temporary folder and sends the kit's files and zip back; the caller then publishes them
exactly as a local build does (locked, crash-safe, `pipeline.publish_files`), so a Ray build
is byte-identical to a serial one.

The cluster is Ray's own convention: `RAY_ADDRESS` names it, else a local instance starts.
Ray is an optional extra (`pip install simkit[ray]`) and is imported only here, only when
`--ray` is given. A worker whose simkit code or library versions differ from the caller's
refuses the task in one line, because its kit would differ. A task whose worker dies
(killed, out of memory) is retried up to twice by Ray, then reported in one line.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

from simkit import __version__
from simkit.errors import SimkitError
from simkit.kitio.cache import Cache, code_digest
from simkit.pipeline import (
    EMIT_LIBRARIES,
    SIMULATE_LIBRARIES,
    BuildResult,
    build,
    find_spec,
    publish_files,
)

#: Ray's retries of a task whose worker process died (Ray's `max_retries`).
TASK_RETRIES = 2
#: Largest total of spec plus named files sent with one task (bytes): a guard against a
#: spec that names a huge file by mistake, not a limit of Ray.
MAX_TASK_BYTES = 512 * 1024 * 1024


class RayUnavailable(SimkitError):
    """`--ray` without the optional extra installed."""


@dataclass(frozen=True)
class Job:
    """One robot as it travels to a worker: the spec, the files it names (POSIX paths
    relative to the spec's folder) and the build options."""

    target: str  # a packaged robot's name, or the spec file's name
    packaged: bool
    spec_bytes: bytes
    named_files: dict[str, bytes]
    options: dict


@dataclass(frozen=True)
class Built:
    """What a worker sends back: the kit's files, its zip and the check findings, or the
    one-line error a local build would have printed."""

    robot: str
    files: dict[str, bytes]
    zip_bytes: bytes
    findings: list
    error: str | None = None
    exit_code: int = 0
    cache_hits: str = ""  # the worker's "local/remote/miss" counts per stage
    warnings: tuple[str, ...] = ()


@dataclass(frozen=True)
class RayBuildResult(BuildResult):
    """A local `BuildResult` plus the worker's cache hits (for the summary line)."""

    cache_hits: str = ""


def fingerprint() -> str:
    """simkit's version and code digest plus every library version that shapes a kit: two
    processes with one fingerprint build byte-identical kits from one spec."""
    parts = [__version__, code_digest()]
    for name in sorted({*EMIT_LIBRARIES, *SIMULATE_LIBRARIES}):
        try:
            parts.append(f"{name}=={metadata.version(name)}")
        except metadata.PackageNotFoundError:
            parts.append(f"{name}==none")
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()


def _strings(value: object) -> list[str]:
    """Every string in a loaded YAML document, in document order."""
    if isinstance(value, str):
        return [value]
    if isinstance(value, dict):
        return [s for item in value.values() for s in _strings(item)]
    if isinstance(value, list):
        return [s for item in value for s in _strings(item)]
    return []


def named_files(spec_path: Path) -> dict[str, bytes]:
    """The files a spec names: every string value that is a relative path to a file inside
    the spec's own folder (meshes, kept source files). Paths leaving the folder are not
    sent; the worker's build then refuses them exactly as a local build would."""
    import yaml

    base = spec_path.parent.resolve()
    try:
        data = yaml.safe_load(spec_path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return {}  # the worker's build reports the spec error in one line
    found: dict[str, bytes] = {}
    for text in _strings(data):
        if not text or "\n" in text or len(text) > 4096 or Path(text).is_absolute():
            continue
        try:
            path = (base / text).resolve()
            inside = path.is_relative_to(base) and path.is_file()
        except (OSError, ValueError):
            continue
        if inside:
            found[path.relative_to(base).as_posix()] = path.read_bytes()
    return dict(sorted(found.items()))


def make_job(target: str, options: dict) -> Job:
    """The job for one target, as `find_spec` resolves it here on the caller."""
    path, shown = find_spec(target)
    packaged = shown.startswith("robots/")
    files = {} if packaged else named_files(path)
    total = path.stat().st_size + sum(len(data) for data in files.values())
    if total > MAX_TASK_BYTES:
        raise SimkitError(
            f"{path}: the spec and the files it names hold {total} bytes, over the "
            f"{MAX_TASK_BYTES} bytes one Ray task carries"
        )
    return Job(target if packaged else path.name, packaged, path.read_bytes(), files, options)


def _write_job(job: Job, folder: Path) -> str:
    """Lay the job's spec and files out under `folder`; returns the target to build."""
    if job.packaged:
        here, _ = find_spec(job.target)
        if here.read_bytes() != job.spec_bytes:
            raise SimkitError(
                f"{job.target}: this worker's packaged spec differs from the caller's"
            )
        return job.target
    for rel, data in job.named_files.items():
        target = (folder / rel).resolve()
        if not target.is_relative_to(folder.resolve()):
            raise SimkitError(f"{rel}: a named file outside the spec's folder")
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
    spec = folder / job.target
    spec.write_bytes(job.spec_bytes)
    return str(spec)


def run_job(job: Job, expected: str) -> Built:
    """The worker's side: refuse a version mismatch, build and check in a private folder,
    and return the kit's bytes (or the one-line error, with the caller's file name)."""
    got = fingerprint()
    if got != expected:
        return Built(
            job.target,
            {},
            b"",
            [],
            f"{job.target}: this Ray worker's simkit or library versions differ from the "
            f"caller's (fingerprint {got[:12]} vs {expected[:12]}); its kit would differ",
            2,
        )
    with tempfile.TemporaryDirectory(prefix="simkit-ray-") as tmp:
        folder = Path(tmp) / "spec"
        folder.mkdir()
        try:
            target = _write_job(job, folder)
            options = dict(job.options)
            if "cache_args" in options:  # the worker's own cache (and its own secret)
                options["cache"] = Cache.at(**options.pop("cache_args"))
            cache = options.setdefault("cache", Cache.at())
            result = build(target, Path(tmp) / "out", remember=False, **options)
            hits = cache.stats.summary() if cache.enabled else ""
            zip_bytes = result.zip_path.read_bytes()
            return Built(
                result.robot,
                result.files,
                zip_bytes,
                result.findings,
                cache_hits=hits,
                warnings=result.warnings,
            )
        except SimkitError as exc:
            message = str(exc).replace(f"{folder}{os.sep}", "")
            return Built(job.target, {}, b"", [], message, exc.exit_code)


def _connect():
    """Ray, connected to `RAY_ADDRESS` or a local instance; one line when it is missing."""
    try:
        import ray
    except ImportError:
        raise RayUnavailable(
            "--ray needs Ray: pip install 'simkit[ray]' (or pip install ray)"
        ) from None
    if not ray.is_initialized():
        ray.init(
            address=os.environ.get("RAY_ADDRESS") or None,
            include_dashboard=False,
            log_to_driver=False,
            configure_logging=False,
        )
    return ray


def build_on_ray(
    targets: Sequence[str],
    out_dir: Path,
    progress: Callable[[str], None] | None = None,
    **options,
) -> list[BuildResult]:
    """Build `targets` as Ray tasks and publish each kit into `out_dir` here, in the order
    given. `options` are `pipeline.build`'s (check, usd_format, step, jobs), except that
    `cache_args` (`Cache.at`'s arguments: folder, readonly, remote URL) replaces `cache`:
    each worker opens its own cache, with its own `$SIMKIT_CACHE_KEY`, which never travels
    with a task."""
    say = progress or (lambda _msg: None)
    jobs = [make_job(target, options) for target in targets]
    ray = _connect()
    remote = ray.remote(num_cpus=1, max_retries=TASK_RETRIES)(run_job)
    expected = fingerprint()
    pending = [remote.remote(job, expected) for job in jobs]
    results = []
    for job, ref in zip(jobs, pending, strict=True):
        built = _gather(ray, job, ref)
        if built.error is not None:
            error = SimkitError(built.error)
            error.exit_code = built.exit_code
            raise error
        say(f"[{built.robot}] built on Ray; publish")
        kit_dir, zip_path, changed = publish_files(
            out_dir, built.robot, built.files, built.zip_bytes
        )
        results.append(
            RayBuildResult(
                built.robot,
                kit_dir,
                zip_path,
                built.files,
                built.findings,
                warnings=built.warnings,
                changed=changed,
                cache_hits=built.cache_hits,
            )
        )
    return results


def _gather(ray, job: Job, ref) -> Built:
    """The task's result; a task whose worker died on every try is one line."""
    try:
        return ray.get(ref)
    except (ray.exceptions.WorkerCrashedError, ray.exceptions.RayTaskError) as exc:
        kind = type(exc).__name__
        raise SimkitError(
            f"{job.target}: the Ray task failed {TASK_RETRIES + 1} times ({kind}); "
            "nothing was published"
        ) from None
    except ray.exceptions.RayError as exc:
        raise SimkitError(f"{job.target}: Ray: {type(exc).__name__}") from None
