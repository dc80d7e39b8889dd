"""The no-op rebuild: `simkit build` of a spec whose inputs did not change since it was built
into the same `--out` writes nothing and says so in one line, before any heavy import.

After each build the pipeline records (`remember`) in the cache folder, under a key of
everything that decides the output: the spec's bytes and resolved path (not how the build
named it: a robot name, a relative or absolute path are one key), simkit's code and templates,
the installed distributions (every `*.dist-info` on `sys.path`) and Python, the output folder
and the options that change output or checking (`--usd-format`, `--no-step`, `--no-check`).
The record lists the files the spec names (meshes), and every published file (kit, zip,
manifest) with its size, SHA-256 and `stat` identity. A rebuild with the same key is a no-op
when every named file and every published file still matches: a file whose size, mtime,
ctime and inode are unchanged is trusted (as git's index does), any other is hashed. Any
difference, a missing record or `--no-cache` runs the full build. The check holds a shared
`flock` of `--out`, so it waits for a build into it to finish. A no-op, like every build, removes
what an interrupted build of the kit left in `--out` (`atomic.leftovers`: `.NAME.<id>.staging`
after a kill -9, ...), taking the lock exclusively for that. Standard library only.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import secrets
import sys
from pathlib import Path

from simkit import __version__
from simkit.errors import SimkitError
from simkit.kitio import atomic, layout, manifest, reuse
from simkit.kitio.resources import data_dir

FORMAT = 1
FOLDER = "noop"
_PACKAGE = Path(__file__).resolve().parents[1]


def options(usd_format: str, step: bool, check: bool) -> dict[str, object]:
    """The build options that change the output or its checking (part of the key)."""
    return {"usd_format": usd_format, "step": step, "check": check}


def cache_root(cache_dir: Path | None) -> Path:
    """The cache folder `kitio.cache.Cache.at` uses: `cache_dir`, else $SIMKIT_CACHE_DIR,
    else the user cache folder (kept in step with `cache.default_dir`, which imports numpy)."""
    if cache_dir:
        return Path(cache_dir).expanduser()
    env = os.environ.get("SIMKIT_CACHE_DIR")
    if env:
        return Path(env).expanduser()
    from platformdirs import user_cache_dir

    return Path(user_cache_dir("simkit", appauthor=False))


def spec_path(target: str) -> Path | None:
    """The spec file `pipeline.find_spec` builds for `target`, or None (then the full build
    reports the problem)."""
    path = Path(target) if target.endswith((".yaml", ".yml")) else None
    if path is None:
        try:
            path = data_dir("robots") / f"{target}.yaml"
        except FileNotFoundError:
            return None
    return path if path.is_file() else None


def _tree_bytes(root: Path, pattern: str) -> list[bytes]:
    return [
        part
        for path in sorted(root.rglob(pattern))
        if path.is_file() and "__pycache__" not in path.parts
        for part in (path.relative_to(root).as_posix().encode(), path.read_bytes())
    ]


def code_digest(package: Path = _PACKAGE, templates: Path | None = None) -> str:
    """SHA-256 of simkit's version, modules (under `package`) and templates."""
    templates = data_dir("templates") if templates is None else templates
    h = hashlib.sha256(__version__.encode())
    for part in (*_tree_bytes(package, "*.py"), *_tree_bytes(templates, "*")):
        h.update(len(part).to_bytes(8, "little"))
        h.update(part)
    return h.hexdigest()


#: `sys.path` as this module first saw it: a library imported later may add folders (Ray
#: adds its `thirdparty_files`), and the key written after a build must equal the key the
#: next `simkit build` computes before importing anything.
_IMPORT_PATH = tuple(sys.path)


def environment() -> list[str]:
    """Python's version and every installed distribution with its version (the names of
    the `*.dist-info` / `*.egg-info` entries on `sys.path` as it was at start-up)."""
    found = {sys.version}
    for entry in _IMPORT_PATH:
        try:
            names = os.listdir(entry or ".")
        except OSError:
            continue
        found.update(n for n in names if n.endswith((".dist-info", ".egg-info")))
    return sorted(found)


def key(target: str, out_dir: Path, options: dict[str, object]) -> str | None:
    """The record's key, or None when `target` names no readable spec file."""
    spec = spec_path(target)
    if spec is None:
        return None
    head = {
        "format": FORMAT,
        "spec": str(spec.resolve()),
        "out": str(Path(out_dir).resolve()),
        "options": options,
        "code": code_digest(),
        "environment": environment(),
    }
    h = hashlib.sha256(json.dumps(head, sort_keys=True).encode("utf-8"))
    h.update(spec.read_bytes())
    return h.hexdigest()


def _record_path(root: Path, digest: str) -> Path:
    return root / FOLDER / digest[:2] / f"{digest}.json"


def _identity(path: Path) -> list[int]:
    st = path.stat()
    return [st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino]


def _entry(path: Path) -> list:
    """[sha256, size, mtime_ns, ctime_ns, inode] of a file."""
    return [manifest.sha256(path.read_bytes()), *_identity(path)]


def _matches(path: Path, entry: list) -> bool:
    """`path` is a plain file with the recorded bytes (trusted on an unchanged `stat`)."""
    try:
        if path.is_symlink() or not path.is_file():
            return False
        if _identity(path) == entry[1:]:
            return True
        return path.stat().st_size == entry[1] and manifest.sha256(path.read_bytes()) == entry[0]
    except OSError:
        return False


def _published(out_dir: Path, robot: str) -> dict[str, Path]:
    """Every published path of `robot` by name: kit files as `KIT/REL`, the zip, the manifest."""
    kit = out_dir / layout.kit_dir_name(robot)
    paths = {f"{kit.name}/{rel}": p for rel, p in manifest.tree(kit).items()}
    for name in (layout.zip_name(robot), manifest.name(robot)):
        paths[name] = out_dir / name
    return paths


def remember(
    cache_dir: Path,
    target: str,
    out_dir: Path,
    options: dict[str, object],
    robot: str,
    named: list[Path],
    checks: tuple[int, int] | None,
) -> None:
    """Record a finished build (call after publishing; a cache that cannot be written only
    costs the next no-op)."""
    tmp = None
    try:
        digest = key(target, out_dir, options)
        if digest is None:
            return
        kit = out_dir / layout.kit_dir_name(robot)
        doc = {
            "format": FORMAT,
            "robot": robot,
            "named": {str(p.resolve()): _entry(p) for p in sorted(set(named)) if p.is_file()},
            "published": {n: _entry(p) for n, p in sorted(_published(out_dir, robot).items())},
            "entries": reuse.entries(kit),
            "checks": list(checks) if checks is not None else None,
        }
        path = _record_path(cache_dir, digest)
        tmp = path.with_name(f".{secrets.token_hex(4)}.tmp")
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(json.dumps(doc, sort_keys=True))
        os.replace(tmp, path)
    except OSError:
        if tmp is not None:
            with contextlib.suppress(OSError):
                tmp.unlink()


def unchanged(
    target: str, out_dir: Path, cache_dir: Path | None, options: dict[str, object]
) -> str | None:
    """The one line of a no-op rebuild, or None when the full build must run."""
    try:
        digest = key(target, out_dir, options)
        if digest is None or not out_dir.is_dir():
            return None
        doc = json.loads(_record_path(cache_root(cache_dir), digest).read_bytes())
        robot, checks = doc["robot"], doc["checks"]
        named, published, entries = doc["named"], doc["published"], doc["entries"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if doc.get("format") != FORMAT:
        return None
    stale = atomic.leftovers(out_dir, robot)
    try:  # a build into out_dir finishes first; exclusive when there is something to remove
        fd = atomic.acquire(out_dir, shared=not stale)
    except (OSError, SimkitError):
        return None
    try:
        line = _verify(out_dir, robot, checks, named, published, entries)
        if line is None or not stale:
            return line
        stale = atomic.leftovers(out_dir, robot)  # no build runs now: all of them are stale
        atomic.clean(out_dir, robot)
        if not stale:
            return line
        names = ", ".join(p.name for p in stale)
        return f"{line}; removed what an interrupted build left: {names}"
    finally:
        atomic.release(fd)


def _verify(
    out_dir: Path,
    robot: str,
    checks: list[int] | None,
    named: dict[str, list],
    published: dict[str, list],
    entries: list[str],
) -> str | None:
    """`unchanged` with the shared lock held."""
    if (out_dir / manifest.journal_name(robot)).exists():
        return None
    kit, zip_path = out_dir / layout.kit_dir_name(robot), out_dir / layout.zip_name(robot)
    paths = _published(out_dir, robot)
    if kit.is_symlink() or sorted(paths) != sorted(published) or reuse.entries(kit) != entries:
        return None
    if not all(_matches(Path(p), entry) for p, entry in named.items()):
        return None
    if not all(_matches(paths[n], entry) for n, entry in published.items()):
        return None
    stand = (
        f"the checks of that build stand ({checks[0]}/{checks[1]} passed)"
        if checks
        else "its checks were skipped (--no-check)"
    )
    files = sum(1 for n in published if n.startswith(f"{kit.name}/"))
    return (
        f"{robot}: nothing changed since the last build (spec, named files, simkit, libraries, "
        f"options): {files} files in {kit}, zip {zip_path}, left as they were; {stand}"
    )
