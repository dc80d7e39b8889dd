"""The import's output folder: a staging folder inside it, removed on every way out, and the
finished files moved into place whole.

- Staging is `OUT/.import-PID-XXXX/`. It is removed when the import ends, fails, or gets
  SIGINT or SIGTERM; one left by a killed process (SIGKILL, power loss) is removed by the next
  import into the same folder (its PID no longer runs).
- Each finished file is written beside its target under a temporary name and renamed over it,
  so a full disk leaves the previous file or none, never a truncated one.
- A folder that cannot be created or written (read-only, full, a file in the way) is one line
  naming the path, not a traceback.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

from simkit.errors import SimkitError
from simkit.kitio import interrupt

PREFIX = ".import-"
#: errors of the disk or of permissions, reported as one line naming the path
DISK_ERRORS = {
    errno.ENOSPC,
    errno.EDQUOT,
    errno.EFBIG,
    errno.EACCES,
    errno.EPERM,
    errno.EROFS,
    errno.ENOTDIR,
    errno.EEXIST,
    errno.EISDIR,
}


def unwritable(exc: OSError, fallback: Path) -> SimkitError:
    """One line for an OSError of writing: the path and the reason."""
    where = exc.filename or fallback
    return SimkitError(f"{where}: cannot write: {exc.strerror or exc}")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's running process
        return True
    return True


def remove_stale(out_dir: Path) -> None:
    """Remove staging folders and partial files whose import no longer runs (a killed one)."""
    for item in sorted(out_dir.glob(f"{PREFIX}*")):
        match = re.match(rf"{re.escape(PREFIX)}(\d+)-", item.name)
        if (match and _alive(int(match[1]))) or item.is_symlink():
            continue
        if item.is_dir():
            shutil.rmtree(item, ignore_errors=True)
        elif item.is_file():  # a file moved into place whole, interrupted
            item.unlink(missing_ok=True)


@contextlib.contextmanager
def staging(out_dir: Path) -> Iterator[Path]:
    """A fresh staging folder inside `out_dir` (created if needed), removed on exit; disk
    and permission errors inside become one line naming the path."""
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        remove_stale(out_dir)
        with interrupt.held():  # a signal here takes effect once `tmp` is known
            tmp = Path(tempfile.mkdtemp(dir=out_dir, prefix=f"{PREFIX}{os.getpid()}-"))
    except OSError as exc:
        raise unwritable(exc, out_dir) from None
    try:
        yield tmp  # SIGINT and SIGTERM raise here (kitio/interrupt.py): the finally runs
    except OSError as exc:
        if exc.errno not in DISK_ERRORS:
            raise
        raise unwritable(exc, out_dir) from None
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def publish(stage: Path, out_dir: Path) -> None:
    """Move every file of `stage` to the same place under `out_dir`, each whole: written under
    a temporary name beside its target, then renamed over it."""
    partial = out_dir / f"{PREFIX}{os.getpid()}-file.part"  # same file system as targets
    for item in sorted(stage.rglob("*")):
        if not item.is_file():
            continue
        target = out_dir / item.relative_to(stage)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(item, partial)
            os.replace(partial, target)
        except OSError as exc:
            partial.unlink(missing_ok=True)
            raise unwritable(exc, target) from None
