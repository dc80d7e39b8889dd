"""Content-addressed disk cache for slow pure steps (link solids, CoACD collision pieces),
optionally in front of a shared remote store.

Design notes (shared/DESIGN.md, "Cache"; issue 3): the key is the SHA-256 of the input bytes,
the step's name and version, the library versions and every parameter, so a change to any of
them misses instead of serving a stale result (onshape-to-robot keyed CoACD by file only).
Entries (entry.py) are `.npz` files of plain arrays, published atomically (`os.replace` of a
temp file in the same folder), and carry their key and a SHA-256 of their content: a
truncated, edited or unreadable entry is a miss, is deleted, and the step recomputes and
rewrites it.

Trust (issue 24; docs/scale-out.md): without `$SIMKIT_CACHE_KEY`, whoever can write the
cache is trusted, as a plain digest can be recomputed. With it, entries carry an HMAC of
their step, key and content, and an entry without a valid one is a miss. `readonly`
(`--cache-readonly`, `$SIMKIT_CACHE_READONLY`) reads and never writes. Paths stored in
entries are confined to their destination where they are written (confine.py).

Location: `--cache-dir`, else `$SIMKIT_CACHE_DIR`, else the user cache folder (XDG on Linux,
via platformdirs); remote: `--remote-cache URL`, else `$SIMKIT_REMOTE_CACHE` (remote.py).
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
import sys
import tempfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

import numpy as np

from simkit import __version__
from simkit.errors import SimkitError
from simkit.kitio.entry import ENV_SECRET, BadEntry, OldFormat, Unauthenticated, secret_from_env
from simkit.kitio.entry import decode as decode_entry
from simkit.kitio.entry import encode as encode_entry
from simkit.kitio.remote import ENV_URL as ENV_REMOTE
from simkit.kitio.remote import RemoteStore, is_url
from simkit.kitio.values import code_digest
from simkit.kitio.values import decode_json as decode_json
from simkit.kitio.values import decode_plain as decode_plain
from simkit.kitio.values import digest as digest
from simkit.kitio.values import encode_json as encode_json
from simkit.kitio.values import encode_plain as encode_plain

ENV_DIR = "SIMKIT_CACHE_DIR"
ENV_READONLY = "SIMKIT_CACHE_READONLY"

Arrays = dict[str, np.ndarray]


def default_dir() -> Path:
    """`$SIMKIT_CACHE_DIR`, else the platform's user cache folder for simkit."""
    env = os.environ.get(ENV_DIR)
    if env:
        return Path(env).expanduser()
    from platformdirs import user_cache_dir  # lazy: only needed when no folder is given

    return Path(user_cache_dir("simkit", appauthor=False))


@functools.cache
def _installed(name: str) -> str | None:
    """A distribution's version, None when absent; looked up once per process (a metadata
    scan costs ~10 ms, and keys are made per link)."""
    from importlib import metadata

    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


def library_version(name: str) -> str:
    """Installed version of a distribution (part of every key that uses that library)."""
    return _installed(name) or "none"


def _canonical(value: object) -> object:
    """Parameters as JSON-able data with a fixed float representation (repr round-trips)."""
    if isinstance(value, Mapping):
        return {str(k): _canonical(v) for k, v in sorted(value.items(), key=lambda kv: str(kv[0]))}
    if isinstance(value, (list, tuple)):
        return [_canonical(v) for v in value]
    if isinstance(value, np.ndarray):
        return hashlib.sha256(np.ascontiguousarray(value).tobytes()).hexdigest()
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, (np.integer,)):
        return int(value)
    if value is None or isinstance(value, (bool, int, str)):
        return value
    raise TypeError(f"cache key cannot hold {type(value).__name__}")


def make_key(
    step: str,
    version: int,
    inputs: list[bytes],
    params: Mapping[str, object],
    libraries: tuple[str, ...] = (),
) -> str:
    """SHA-256 hex key of the input bytes, step name and version, simkit and library versions,
    and every parameter."""
    h = hashlib.sha256()
    head = {
        "step": step,
        "version": version,
        "simkit": __version__,
        "libraries": {name: library_version(name) for name in sorted(libraries)},
        "params": _canonical(params),
    }
    h.update(json.dumps(head, sort_keys=True).encode("utf-8"))
    for blob in inputs:
        h.update(len(blob).to_bytes(8, "little"))
        h.update(hashlib.sha256(blob).digest())
    return h.hexdigest()


def readonly_from_env() -> bool:
    """`$SIMKIT_CACHE_READONLY` set to 1, true or yes."""
    return os.environ.get(ENV_READONLY, "").strip().lower() in ("1", "true", "yes")


@dataclass
class Stats:
    """Per step: local hits, remote hits, misses and repaired (bad) entries, in the order
    the steps were first asked for; the build's summary line and tests read them."""

    hits: dict[str, int] = field(default_factory=dict)
    misses: dict[str, int] = field(default_factory=dict)
    repaired: dict[str, int] = field(default_factory=dict)
    remote: dict[str, int] = field(default_factory=dict)
    steps: list[str] = field(default_factory=list)

    def bump(self, table: dict[str, int], step: str) -> None:
        table[step] = table.get(step, 0) + 1
        if step not in self.steps:
            self.steps.append(step)

    def summary(self) -> str:
        """`step local/remote/miss, ...`, e.g. `link_solid 0/3/0, emit 0/1/0`."""
        return ", ".join(
            f"{s} {self.hits.get(s, 0)}/{self.remote.get(s, 0)}/{self.misses.get(s, 0)}"
            for s in self.steps
        )


@dataclass
class Cache:
    """A cache folder, optionally in front of a remote store. `enabled=False`
    (`--no-cache`) computes every step and stores nothing; `readonly` reads and never
    writes (nor repairs); `secret` (`$SIMKIT_CACHE_KEY`) tags every entry written and
    refuses entries without a valid tag (entry.py)."""

    root: Path | None
    enabled: bool = True
    stats: Stats = field(default_factory=Stats)
    warned: set[str] = field(default_factory=set)
    readonly: bool = False
    secret: bytes | None = None
    remote: RemoteStore | None = None
    #: (step, key) of remote entries that failed verification: the one overwrite allowed.
    bad_remote: set[tuple[str, str]] = field(default_factory=set)
    #: Where the last hit came from ("local" or "remote"), for `reject`.
    last_source: str = ""

    @staticmethod
    def at(
        root: Path | str | None = None,
        enabled: bool = True,
        readonly: bool | None = None,
        remote: str | None = None,
    ) -> Cache:
        """The cache at `root` (default: env, then user cache folder). `readonly` and
        `remote` default to `$SIMKIT_CACHE_READONLY` and `$SIMKIT_REMOTE_CACHE`; the
        secret is always `$SIMKIT_CACHE_KEY`. A URL as `root` is a one-line error."""
        given = ("--cache-dir", str(root)) if root else (f"${ENV_DIR}", os.environ.get(ENV_DIR))
        if given[1] and is_url(given[1]):
            raise SimkitError(
                f"{given[0]} {given[1]}: is a URL; the cache folder is local, give the URL "
                "to --remote-cache (or $SIMKIT_REMOTE_CACHE)"
            )
        cache = Cache(
            Path(root).expanduser() if root else default_dir(),
            enabled,
            readonly=readonly_from_env() if readonly is None else readonly,
            secret=secret_from_env(),
        )
        url = os.environ.get(ENV_REMOTE, "") if remote is None else remote
        if enabled and url:
            cache.remote = RemoteStore(url, lambda m: cache._warn(m, "<remote>"))
        return cache

    @staticmethod
    def disabled() -> Cache:
        return Cache(None, enabled=False)

    def path(self, step: str, key: str) -> Path:
        assert self.root is not None
        return self.root / step / key[:2] / f"{key}.npz"

    def get(self, step: str, key: str) -> Arrays | None:
        """The stored arrays, or None on a miss: the local folder first, then the remote
        store (a verified remote entry is copied into the local folder). An entry that is
        not a readable file holding this key's arrays (corrupt, a folder, another key's
        content) is removed, counted as repaired, and reported once with a one-line
        warning; with a secret set, an untagged or mistagged entry is a miss with one
        warning."""
        if not self.enabled:
            return None
        found = self._local(step, key)
        if found is not None:
            self.stats.bump(self.stats.hits, step)
            self.last_source = "local"
            return found
        found = self._fetch(step, key)
        if found is not None:
            self.stats.bump(self.stats.remote, step)
            self.last_source = "remote"
            return found
        self.stats.bump(self.stats.misses, step)
        return None

    def _local(self, step: str, key: str) -> Arrays | None:
        path = self.path(step, key)
        try:
            present, plain = path.is_symlink() or path.exists(), path.is_file()
        except OSError:  # an unreadable cache folder: a miss
            return None
        if not present:
            return None
        if plain and not path.is_symlink():
            try:
                return self._verified(path.read_bytes(), step, key)
            except (OSError, BadEntry):
                pass
            except (OldFormat, Unauthenticated):
                return None  # `put` replaces it
        self._repair(step, path)
        return None

    def _verified(self, data: bytes, step: str, key: str) -> Arrays:
        """`entry.decode`, warning once when a secret refuses an entry's tag."""
        try:
            return decode_entry(data, step, key, self.secret)
        except Unauthenticated:
            self._warn(
                f"cache entries without a valid {ENV_SECRET} tag (written without the key, "
                f"or forged) are recomputed; the first was a '{step}' entry",
                "<tag>",
            )
            raise

    def _fetch(self, step: str, key: str) -> Arrays | None:
        """A verified entry from the remote store, copied into the local folder."""
        if self.remote is None:
            return None
        data = self.remote.fetch(step, key)
        if data is None:
            return None
        try:
            arrays = self._verified(data, step, key)
        except (BadEntry, OldFormat, Unauthenticated) as exc:
            self.bad_remote.add((step, key))
            if isinstance(exc, BadEntry):
                self._warn(
                    f"a '{step}' entry in the remote cache failed verification; recomputed",
                    "<remote-bad>",
                )
            return None
        if not self.readonly:
            self._write_local(step, key, data)
        return arrays

    def reject(self, step: str, key: str, exc: Exception) -> None:
        """The entry `get` just returned cannot be used by its stage (it is well formed but
        holds, e.g., a path that would leave the kit): a repaired miss with one warning,
        and the remote copy may be replaced by the recomputed result."""
        table = self.stats.remote if self.last_source == "remote" else self.stats.hits
        table[step] -= 1
        if not table[step]:
            del table[step]
        self.stats.bump(self.stats.misses, step)
        self.bad_remote.add((step, key))
        path = self.path(step, key)
        if self.readonly or not path.is_file():
            self.stats.bump(self.stats.repaired, step)
            self._warn(f"a '{step}' cache entry was refused ({exc}); recomputed", step)
        else:
            self._repair(step, path)

    def _repair(self, step: str, path: Path) -> None:
        """Remove a bad entry (file, link or folder) so the step rewrites it (not when
        read-only: the entry is a miss and stays)."""
        self.stats.bump(self.stats.repaired, step)
        if self.readonly:
            self._warn(f"a '{step}' cache entry was unreadable or not its key's: {path}", step)
            return
        try:
            if path.is_dir() and not path.is_symlink():
                import shutil

                shutil.rmtree(path)
            else:
                path.unlink(missing_ok=True)
        except OSError as exc:
            self._warn(f"cannot remove a bad '{step}' cache entry ({exc.strerror}): {path}", step)
            return
        self._warn(
            f"a '{step}' cache entry was unreadable or not its key's; recomputed: {path}", step
        )

    def _warn(self, message: str, topic: str) -> None:
        """One line on stderr, once per topic (a step's repairs, an unwritable folder)."""
        if topic not in self.warned:
            self.warned.add(topic)
            print(f"simkit: warning: {message}", file=sys.stderr)

    def put(self, step: str, key: str, arrays: Arrays) -> None:
        """Store in the local folder and the remote store (nothing when read-only). The
        entry holds its key inside its digest, and a tag when a secret is set. A cache that
        cannot be written (read-only, full) is a warning, never a failed build."""
        if not self.enabled:
            return
        data = encode_entry(step, key, arrays, self.secret)
        if self.readonly:
            return
        self._write_local(step, key, data)
        if self.remote is not None:
            replace = (step, key) in self.bad_remote
            self.remote.store(step, key, data, replace=replace)
            self.bad_remote.discard((step, key))

    def _write_local(self, step: str, key: str, data: bytes) -> None:
        """Write a temp file beside the entry, then `os.replace` it: a full disk or a
        killed build leaves no truncated entry."""
        path = self.path(step, key)
        tmp = None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            if path.is_dir() and not path.is_symlink():
                self._repair(step, path)
            fd, tmp = tempfile.mkstemp(prefix=f".{key[:16]}.", suffix=".tmp", dir=path.parent)
            with os.fdopen(fd, "wb") as handle:
                handle.write(data)
            os.replace(tmp, path)
            tmp = None
        except OSError as exc:
            why = f"cache folder {self.root} is not writable ({exc.strerror}); results not cached"
            self._warn(why, "<write>")
        finally:  # on every way out, an interrupt included: no temp file left
            if tmp is not None:
                Path(tmp).unlink(missing_ok=True)

    def memo(self, step: str, key: str, compute: Callable[[], Arrays]) -> Arrays:
        """`get`, else `compute` and `put`."""
        found = self.get(step, key)
        if found is not None:
            return found
        result = compute()
        self.put(step, key, result)
        return result


T = TypeVar("T")
#: What a stage's `decode` raises on an entry it cannot use (confine.UnsafePath included).
_UNUSABLE = (KeyError, IndexError, TypeError, ValueError, UnicodeDecodeError)


def cached_stage(
    cache: Cache,
    step: str,
    inputs: list[bytes],
    compute: Callable[[], T],
    encode: Callable[[T], Arrays | None],
    decode: Callable[[Arrays], T],
    libraries: tuple[str, ...] = (),
    params: Mapping[str, object] | None = None,
) -> T:
    """The one wrapper every cached stage goes through: `compute()` unless an entry for the
    same inputs exists. The key holds `inputs` (bytes), simkit's source digest (any code
    change misses), the library versions and `params`. `encode` returns the arrays to store,
    or None when a result must not be stored (e.g. failed checks); `decode` rebuilds the
    value from a stored entry."""
    if not cache.enabled:
        return compute()
    key = make_key(step, 1, [code_digest().encode(), *inputs], params or {}, libraries)
    found = cache.get(step, key)
    if found is not None:
        try:
            return decode(found)
        except _UNUSABLE as exc:  # verified bytes the stage cannot use, e.g. a stored `../`
            cache.reject(step, key, exc)
    value = compute()
    arrays = encode(value)
    if arrays is None:
        return value
    cache.put(step, key, arrays)
    # what a later hit returns, so a cold and a warm build hand identical values (same types,
    # e.g. float not numpy.float64) to the next stage and its cache keys
    return decode(arrays)


def library_versions(names: tuple[str, ...]) -> dict[str, str | None]:
    """Installed version of each distribution, None when absent (robot.json provenance)."""
    return {name: _installed(name) for name in names}
