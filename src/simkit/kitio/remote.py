"""A remote build cache behind the local one (issue 26), as Bazel's `--remote_cache`.

`--remote-cache URL` / `$SIMKIT_REMOTE_CACHE` names an fsspec URL (`s3://bucket/prefix` is
the tested one); fsspec and s3fs are the optional extra `simkit[remote]`, imported only
here and only when a URL is given. Credentials and endpoint come from the standard AWS
environment and config files (`AWS_ENDPOINT_URL` for a local server).

Objects use the local layout, `PREFIX/STEP/KK/KEY.npz`, and the entry format of entry.py;
`cache.Cache` verifies what it reads. Writes are write-once: a conditional put
(`If-None-Match: *`) where the store honours it, else an upload to `PREFIX/tmp/` and a copy
when the entry is absent. The one overwrite is `replace=True`: the verified result over an
entry that failed verification.

A store that cannot be reached, or refuses reads, is dropped for the rest of the process
with one warning; one that refuses writes is read-only from then on, with one warning.
Neither fails a build. A connection attempt times out after `CONNECT_TIMEOUT_S`.
"""

from __future__ import annotations

import errno
import secrets
from collections.abc import Callable

from simkit.errors import SimkitError

ENV_URL = "SIMKIT_REMOTE_CACHE"
#: Seconds to open a connection (the issue's limit is 10).
CONNECT_TIMEOUT_S = 5
#: Seconds to wait for a response once connected.
READ_TIMEOUT_S = 60
#: Errors by which a store says it does not support conditional writes.
_UNSUPPORTED = (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP)


def is_url(text: str) -> bool:
    """A `scheme://...` location rather than a local folder."""
    return "://" in text


def _filesystem(url: str) -> tuple[object, str]:
    """The fsspec filesystem and root path for `url` (one-line SimkitError when unusable)."""
    try:
        import fsspec
    except ImportError:
        raise SimkitError(
            f"--remote-cache {url}: needs fsspec and s3fs (pip install 'simkit[remote]')"
        ) from None
    protocol = url.split("://", 1)[0].lower()
    options: dict[str, object] = {}
    if protocol in ("s3", "s3a"):
        options = {
            "skip_instance_cache": True,
            "use_listings_cache": False,
            "config_kwargs": {
                "connect_timeout": CONNECT_TIMEOUT_S,
                "read_timeout": READ_TIMEOUT_S,
                "retries": {"max_attempts": 1, "mode": "standard"},
            },
        }
    if protocol in ("file", "local"):
        options = {"auto_mkdir": True}  # a shared folder: create STEP/KK/ as needed
    try:
        fs, root = fsspec.core.url_to_fs(url, **options)
    except ImportError as exc:
        raise SimkitError(f"--remote-cache {url}: {_first_line(exc)}") from None
    except (ValueError, TypeError, OSError) as exc:
        raise SimkitError(f"--remote-cache {url}: not a usable URL: {_first_line(exc)}") from None
    if protocol in ("s3", "s3a"):
        fs.retries = 1  # type: ignore[attr-defined]  # botocore retries; no second loop
    return fs, root.rstrip("/")


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip() or type(exc).__name__
    return text.splitlines()[0]


class RemoteStore:
    """Entries in an fsspec store. `conditional`: None learns whether the store takes
    `If-None-Match: *`; False always uses the upload-and-copy path."""

    def __init__(
        self,
        url: str,
        warn: Callable[[str], None],
        conditional: bool | None = None,
    ) -> None:
        self.url = url
        self.fs, self.root = _filesystem(url)
        self.conditional = conditional
        self.readable = True
        self.writable = True
        self._warn = warn

    def path(self, step: str, key: str) -> str:
        return f"{self.root}/{step}/{key[:2]}/{key}.npz"

    def fetch(self, step: str, key: str) -> bytes | None:
        """The stored bytes, or None when absent or the store is unusable."""
        if not self.readable:
            return None
        try:
            return self.fs.cat_file(self.path(step, key))  # type: ignore[attr-defined]
        except FileNotFoundError:
            return None
        except Exception as exc:  # any store failure: degrade to the local cache
            self._down(exc)
            return None

    def store(self, step: str, key: str, data: bytes, replace: bool = False) -> None:
        """Write once; `replace`: overwrite an entry that failed verification."""
        if not (self.readable and self.writable):
            return
        path = self.path(step, key)
        try:
            if replace:
                self.fs.pipe_file(path, data)  # type: ignore[attr-defined]
            elif self.conditional is False:
                self._copy_in(path, key, data)
            else:
                self._conditional_put(path, key, data)
        except FileExistsError:
            return  # another writer stored it first: write-once kept
        except Exception as exc:  # refused or unreachable: keep results local
            self.writable = False
            self._warn(
                f"remote cache {self.url} refused a write ({_first_line(exc)}); "
                "results are cached locally only"
            )

    def _conditional_put(self, path: str, key: str, data: bytes) -> None:
        try:
            self.fs.pipe_file(path, data, mode="create")  # type: ignore[attr-defined]
        except (TypeError, NotImplementedError):
            self._fallback(path, key, data)
            return
        except FileExistsError:
            raise
        except OSError as exc:
            if self.conditional is None and exc.errno in _UNSUPPORTED:
                self._fallback(path, key, data)
                return
            raise
        self.conditional = True

    def _fallback(self, path: str, key: str, data: bytes) -> None:
        self.conditional = False
        self._copy_in(path, key, data)

    def _copy_in(self, path: str, key: str, data: bytes) -> None:
        """Upload to a temporary key, then copy to `path` unless an entry is there."""
        fs = self.fs
        tmp = f"{self.root}/tmp/{key}.{secrets.token_hex(8)}.npz"
        fs.pipe_file(tmp, data)  # type: ignore[attr-defined]
        try:
            if not fs.exists(path):  # type: ignore[attr-defined]
                fs.copy(tmp, path)  # type: ignore[attr-defined]
        finally:
            fs.rm_file(tmp)  # type: ignore[attr-defined]

    def _down(self, exc: BaseException) -> None:
        self.readable = False
        self._warn(
            f"remote cache {self.url} is unreachable or refused a read "
            f"({_first_line(exc)}); using the local cache only"
        )
