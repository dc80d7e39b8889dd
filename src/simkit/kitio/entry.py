"""The bytes of one cache entry, the same on disk and in a remote store (issues 13, 24, 26).

An entry is an `.npz` of plain arrays (loaded with `allow_pickle=False`) plus three fields:
`__key__` (the cache key it answers), `__sha256__` (a SHA-256 of every array, the key
included) and, when `$SIMKIT_CACHE_KEY` holds a secret, `__hmac__`: HMAC-SHA256 of the step,
the key and that digest. The digest catches damage; only the tag catches forgery, since
anyone who can write the cache can recompute a plain digest. With a secret set, an entry
without a valid tag is refused, so an entry cannot be forged nor replayed under another key.
"""

from __future__ import annotations

import hashlib
import hmac
import io
import os
import zipfile

import numpy as np

ENV_SECRET = "SIMKIT_CACHE_KEY"
DIGEST = "__sha256__"
KEY = "__key__"
TAG = "__hmac__"

Arrays = dict[str, np.ndarray]


class BadEntry(Exception):
    """Unreadable, damaged, or another key's content."""


class OldFormat(Exception):
    """An intact entry from a simkit that did not store keys: a silent miss."""


class Unauthenticated(Exception):
    """A secret is set and the entry carries no valid tag for this step and key."""


def secret_from_env() -> bytes | None:
    """The HMAC secret from `$SIMKIT_CACHE_KEY`, None when unset or empty."""
    value = os.environ.get(ENV_SECRET, "")
    return value.encode("utf-8") if value else None


def content_digest(arrays: Arrays) -> str:
    """SHA-256 hex of every array's name, dtype, shape and bytes, in name order."""
    h = hashlib.sha256()
    for name in sorted(arrays):
        arr = np.ascontiguousarray(arrays[name])
        h.update(f"{name}|{arr.dtype.str}|{arr.shape}|".encode())
        h.update(arr.tobytes())
    return h.hexdigest()


def tag(secret: bytes, step: str, key: str, digest: str) -> str:
    """HMAC-SHA256 hex binding the entry's step, key and content digest."""
    message = f"simkit-cache-v1\0{step}\0{key}\0{digest}".encode("ascii")
    return hmac.new(secret, message, hashlib.sha256).hexdigest()


def _ascii(text: str) -> np.ndarray:
    return np.frombuffer(text.encode("ascii"), dtype=np.uint8)


def encode(step: str, key: str, arrays: Arrays, secret: bytes | None) -> bytes:
    """The entry's bytes: `arrays`, the key, the digest and (with a secret) the tag."""
    payload = {name: np.ascontiguousarray(a) for name, a in arrays.items()}
    if any(a.dtype.hasobject for a in payload.values()):
        raise TypeError("cache entries hold plain arrays only (no pickled objects)")
    payload[KEY] = _ascii(key)
    digest = content_digest(payload)
    payload[DIGEST] = _ascii(digest)
    if secret is not None:
        payload[TAG] = _ascii(tag(secret, step, key, digest))
    buf = io.BytesIO()
    np.savez(buf, **payload)
    return buf.getvalue()


def decode(data: bytes, step: str, key: str, secret: bytes | None) -> Arrays:
    """The arrays of a verified entry. Raises BadEntry (damaged, another key's), OldFormat
    (intact but keyless) or Unauthenticated (a secret is set and the tag is missing or
    wrong)."""
    try:
        with np.load(io.BytesIO(data), allow_pickle=False) as npz:
            if not isinstance(npz, np.lib.npyio.NpzFile):
                raise BadEntry
            arrays = {name: npz[name] for name in npz.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile, RuntimeError):
        raise BadEntry from None
    stored = arrays.pop(DIGEST, None)
    found = arrays.pop(TAG, None)
    digest = content_digest(arrays)
    if stored is None or stored.tobytes().decode("ascii", "replace") != digest:
        raise BadEntry
    bound = arrays.pop(KEY, None)
    if bound is None:  # written before entries held their key: an old format, not damage
        raise OldFormat
    if bound.tobytes() != key.encode("ascii"):
        raise BadEntry
    if secret is not None:
        given = found.tobytes() if found is not None else b""
        if not hmac.compare_digest(given, tag(secret, step, key, digest).encode("ascii")):
            raise Unauthenticated
    return arrays
