"""Digests and plain-data encodings for the robot-level cached stages (moved out of
cache.py; cache.py re-exports every public name, so stages import them from there)."""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from simkit import __version__

Arrays = dict[str, np.ndarray]


def encode_json(value: object) -> np.ndarray:
    """JSON data as a uint8 array, so metadata travels in the npz without pickle."""
    return np.frombuffer(json.dumps(value).encode("utf-8"), dtype=np.uint8)


def decode_json(arr: np.ndarray) -> object:
    return json.loads(np.asarray(arr, dtype=np.uint8).tobytes().decode("utf-8"))


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
