"""Content-addressed disk cache for slow pure steps (link solids, CoACD collision pieces).

Design notes (shared/DESIGN.md, "Cache"; issue 3): the key is the SHA-256 of the input bytes,
the step's name and version, the library versions and every parameter, so a change to any of
them misses instead of serving a stale result (onshape-to-robot keyed CoACD by file only).
Entries are `.npz` files written with `allow_pickle=False` semantics (plain arrays, JSON as
uint8 bytes), published atomically (`os.replace` of a temp file in the same folder), and carry
a SHA-256 of their own content: a truncated, edited or unreadable entry is a miss, is deleted,
and the step recomputes and rewrites it.

Location: `--cache-dir`, else `$SIMKIT_CACHE_DIR`, else the user cache folder (XDG on Linux,
via platformdirs).
"""

from __future__ import annotations

import functools
import hashlib
import io
import json
import os
import sys
import tempfile
import zipfile
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

import numpy as np

from simkit import __version__

ENV_DIR = "SIMKIT_CACHE_DIR"
_DIGEST = "__sha256__"
_KEY = "__key__"

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


def _content_digest(arrays: Arrays) -> str:
    h = hashlib.sha256()
    for name in sorted(arrays):
        arr = np.ascontiguousarray(arrays[name])
        h.update(f"{name}|{arr.dtype.str}|{arr.shape}|".encode())
        h.update(arr.tobytes())
    return h.hexdigest()


def encode_json(value: object) -> np.ndarray:
    """JSON data as a uint8 array, so metadata travels in the npz without pickle."""
    return np.frombuffer(json.dumps(value).encode("utf-8"), dtype=np.uint8)


def decode_json(arr: np.ndarray) -> object:
    return json.loads(np.asarray(arr, dtype=np.uint8).tobytes().decode("utf-8"))


@dataclass
class Stats:
    """Hits, misses and repaired (corrupt) entries per step, for tests and the bench."""

    hits: dict[str, int] = field(default_factory=dict)
    misses: dict[str, int] = field(default_factory=dict)
    repaired: dict[str, int] = field(default_factory=dict)

    def bump(self, table: dict[str, int], step: str) -> None:
        table[step] = table.get(step, 0) + 1


@dataclass
class Cache:
    """A cache folder; `enabled=False` (`--no-cache`) computes every step and stores nothing."""

    root: Path | None
    enabled: bool = True
    stats: Stats = field(default_factory=Stats)
    warned: set[str] = field(default_factory=set)

    @staticmethod
    def at(root: Path | str | None = None, enabled: bool = True) -> Cache:
        """The cache at `root` (default: env, then user cache folder)."""
        return Cache(Path(root).expanduser() if root else default_dir(), enabled)

    @staticmethod
    def disabled() -> Cache:
        return Cache(None, enabled=False)

    def path(self, step: str, key: str) -> Path:
        assert self.root is not None
        return self.root / step / key[:2] / f"{key}.npz"

    def get(self, step: str, key: str) -> Arrays | None:
        """The stored arrays, or None on a miss. An entry that is not a readable file holding
        this key's arrays (corrupt, a folder, another key's content) is removed, counted as
        repaired, and reported once with a one-line warning."""
        if not self.enabled:
            return None
        path = self.path(step, key)
        try:
            present, plain = path.is_symlink() or path.exists(), path.is_file()
        except OSError:  # an unreadable cache folder: a miss
            present = plain = False
        if not present:
            self.stats.bump(self.stats.misses, step)
            return None
        arrays = None
        if plain and not path.is_symlink():
            try:
                arrays = _decode(path.read_bytes(), key)
            except OSError:
                arrays = None
            except _OldFormat:
                self.stats.bump(self.stats.misses, step)
                return None  # `put` replaces it
        if arrays is None:
            self._repair(step, path)
            self.stats.bump(self.stats.misses, step)
            return None
        self.stats.bump(self.stats.hits, step)
        return arrays

    def _repair(self, step: str, path: Path) -> None:
        """Remove a bad entry (file, link or folder) so the step rewrites it."""
        self.stats.bump(self.stats.repaired, step)
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
        """Store atomically: write a temp file beside the entry, then `os.replace` it. The
        entry holds its key, inside its digest. A cache that cannot be written (read-only,
        full) is a warning, never a failed build."""
        if not self.enabled:
            return
        payload = {name: np.ascontiguousarray(a) for name, a in arrays.items()}
        if any(a.dtype.hasobject for a in payload.values()):
            raise TypeError("cache entries hold plain arrays only (no pickled objects)")
        payload[_KEY] = np.frombuffer(key.encode("ascii"), dtype=np.uint8)
        payload[_DIGEST] = np.frombuffer(_content_digest(payload).encode("ascii"), dtype=np.uint8)
        buf = io.BytesIO()
        np.savez(buf, **payload)
        path = self.path(step, key)
        tmp = None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            if path.is_dir() and not path.is_symlink():
                self._repair(step, path)
            fd, tmp = tempfile.mkstemp(prefix=f".{key[:16]}.", suffix=".tmp", dir=path.parent)
            with os.fdopen(fd, "wb") as handle:
                handle.write(buf.getvalue())
            os.replace(tmp, path)
        except OSError as exc:
            if tmp is not None:
                Path(tmp).unlink(missing_ok=True)
            why = f"cache folder {self.root} is not writable ({exc.strerror}); results not cached"
            self._warn(why, "<write>")

    def memo(self, step: str, key: str, compute: Callable[[], Arrays]) -> Arrays:
        """`get`, else `compute` and `put`."""
        found = self.get(step, key)
        if found is not None:
            return found
        result = compute()
        self.put(step, key, result)
        return result


def _decode(data: bytes, key: str) -> Arrays | None:
    """Arrays of an entry, or None when it is unreadable, its digest does not match, or it
    holds another key's content (entries are bound to their key)."""
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as npz:
            if not isinstance(npz, np.lib.npyio.NpzFile):
                return None
            arrays = {name: npz[name] for name in npz.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, RuntimeError):
        return None
    stored = arrays.pop(_DIGEST, None)
    if stored is None or stored.tobytes().decode("ascii", "replace") != _content_digest(arrays):
        return None
    bound = arrays.pop(_KEY, None)
    if bound is None:  # written before entries held their key: an old format, not damage
        raise _OldFormat
    if bound.tobytes() != key.encode("ascii"):
        return None
    return arrays


class _OldFormat(Exception):
    """An intact entry from a simkit that did not store keys: a silent miss."""


# --- whole-robot derive steps -----------------------------------------------------------


def code_digest() -> str:
    """SHA-256 of simkit's own source files: the version of a robot-level step, so editing
    any module (a step or what it calls) invalidates its cached results."""
    global _CODE_DIGEST
    if _CODE_DIGEST is None:
        package = Path(__file__).resolve().parents[1]  # every module of simkit
        h = hashlib.sha256(__version__.encode())
        for path in sorted(package.rglob("*.py")):
            h.update(path.relative_to(package).as_posix().encode())
            h.update(path.read_bytes())
        _CODE_DIGEST = h.hexdigest()
    return _CODE_DIGEST


_CODE_DIGEST: str | None = None


def digest(value: object) -> str:
    """SHA-256 of a value's content: dataclasses by field, pydantic models by dump, arrays by
    bytes, floats by repr, numpy scalars as the Python numbers they equal (a cached step
    returns `float` where a computed one returned `np.float64`: both must give one key, or
    the first rebuild after a cold build misses). Used to key a step on the whole `Robot`."""
    from dataclasses import fields, is_dataclass

    h = hashlib.sha256()

    def feed(v: object) -> None:
        if is_dataclass(v) and not isinstance(v, type):
            h.update(f"<{type(v).__name__}".encode())
            for f in fields(v):
                h.update(f.name.encode())
                feed(getattr(v, f.name))
            h.update(b">")
        elif hasattr(v, "model_dump"):
            feed(v.model_dump())  # type: ignore[union-attr]
        elif isinstance(v, np.generic):  # a numpy scalar is its value: JSON round trips agree
            feed(v.item())
        elif isinstance(v, np.ndarray):
            h.update(f"a{v.dtype.str}{v.shape}".encode())
            h.update(np.ascontiguousarray(v).tobytes())
        elif isinstance(v, Mapping):
            h.update(b"{")
            for k in sorted(v, key=str):
                feed(str(k))
                feed(v[k])
            h.update(b"}")
        elif isinstance(v, (list, tuple)):
            h.update(b"[" if isinstance(v, list) else b"(")
            for item in v:
                feed(item)
            h.update(b"]")
        elif isinstance(v, np.generic) and not isinstance(v, np.ndarray):
            feed(v.item())  # a numpy scalar digests as the Python number it equals
        else:
            h.update(f"{type(v).__name__}:{v!r};".encode())

    feed(value)
    return h.hexdigest()


T = TypeVar("T")


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
        return decode(found)
    value = compute()
    arrays = encode(value)
    if arrays is None:
        return value
    cache.put(step, key, arrays)
    # what a later hit returns, so a cold and a warm build hand identical values (same types,
    # e.g. float not numpy.float64) to the next stage and its cache keys
    return decode(arrays)


def encode_plain(value: object) -> Arrays | None:
    """Plain data (dicts with str keys, lists, str, bool, int, float64, numpy arrays) as
    cache arrays: a JSON skeleton plus one array per ndarray. None for anything JSON cannot
    hold exactly (tuples, other objects), so such a value is simply not cached."""
    arrays: Arrays = {}
    try:
        skeleton = _split(value, arrays)
        if json.loads(json.dumps(skeleton)) != skeleton:
            return None
    except (TypeError, ValueError):
        return None
    return {"skeleton": encode_json(skeleton), **arrays}


def decode_plain(arrays: Arrays) -> object:
    """The value `encode_plain` stored."""
    return _join(decode_json(arrays["skeleton"]), arrays)


def library_versions(names: tuple[str, ...]) -> dict[str, str | None]:
    """Installed version of each distribution, None when absent (robot.json provenance)."""
    return {name: _installed(name) for name in names}


_ARRAY = "__ndarray__"


def _split(value: object, arrays: Arrays) -> object:
    """JSON skeleton of `value` with each numpy array moved into `arrays` (raises TypeError
    for anything JSON cannot hold exactly, such as tuples)."""
    if isinstance(value, np.ndarray):
        if value.dtype.hasobject:
            raise TypeError("object array")
        name = f"a{len(arrays)}"
        arrays[name] = value
        return {_ARRAY: name}
    if isinstance(value, dict):
        if not all(isinstance(k, str) for k in value) or _ARRAY in value:
            raise TypeError("keys")
        return {k: _split(v, arrays) for k, v in value.items()}
    if isinstance(value, list):
        return [_split(v, arrays) for v in value]
    if value is None or type(value) in (bool, int, float, str):
        return value
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating) and value.dtype == np.float64:
        return float(value)  # the same double; emitters format both alike
    raise TypeError(type(value).__name__)


def _join(value: object, arrays: Mapping[str, np.ndarray]) -> object:
    if isinstance(value, dict):
        if set(value) == {_ARRAY}:
            return arrays[value[_ARRAY]]
        return {k: _join(v, arrays) for k, v in value.items()}
    if isinstance(value, list):
        return [_join(v, arrays) for v in value]
    return value
