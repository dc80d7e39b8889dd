"""The import's output folder: a staging folder inside it, removed on every way out, and the
finished files moved into place whole.

- Staging is `OUT/.import-PID-XXXX/`. It is removed when the import ends, fails, or gets
  SIGINT or SIGTERM; one left by a killed process (SIGKILL, power loss) is removed by the next
  import into the same folder (its PID no longer runs).
- The finished files are all copied beside their targets under temporary names first, then
  renamed over them (renames write no data). A failure on the way (a full disk, any error,
  SIGTERM) puts back every file it replaced and removes every one it added, so an import that
  fails leaves `--out` as it was: no spec, no kept source, no mesh (issue 32, class 10).
- An `--out` folder the import created is removed again when the import fails.
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


def unwritable(exc: OSError, fallback: Path, stage: Path | None = None) -> SimkitError:
    """One line for an OSError of writing: the path and the reason. A file of the staging
    folder `stage` is named by its place under the output folder (`fallback`): the user
    never sees the staging folder."""
    where = Path(exc.filename) if exc.filename else fallback
    if stage is not None and where.is_relative_to(stage):
        where = fallback / where.relative_to(stage)
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
    made = [p for p in (out_dir, *out_dir.parents) if not p.exists()]  # deepest first
    tmp: Path | None = None
    try:
        try:
            out_dir.mkdir(parents=True, exist_ok=True)
            remove_stale(out_dir)
            with interrupt.held():  # a signal here takes effect once `tmp` is known
                tmp = Path(tempfile.mkdtemp(dir=out_dir, prefix=f"{PREFIX}{os.getpid()}-"))
        except OSError as exc:
            raise unwritable(exc, out_dir) from None
        yield tmp  # SIGINT and SIGTERM raise here (kitio/interrupt.py): the except runs
    except BaseException as exc:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)
        _remove_empty(made)  # a failed import leaves no folder it made
        if isinstance(exc, OSError) and exc.errno in DISK_ERRORS:
            raise unwritable(exc, out_dir, tmp) from None
        raise
    finally:
        if tmp is not None:
            shutil.rmtree(tmp, ignore_errors=True)


def _remove_empty(folders: list[Path]) -> None:
    """Remove the folders an import made, deepest first, each only while empty."""
    for folder in folders:
        try:
            folder.rmdir()
        except OSError:
            return


def publish(stage: Path, out_dir: Path) -> None:
    """Move every file of `stage` to the same place under `out_dir`, all or nothing: each
    copied beside its target under a temporary name, then all renamed over their targets
    (the replaced files kept aside until the last rename). On any failure every target is
    as it was and nothing the import made is left."""
    files = sorted(item for item in stage.rglob("*") if item.is_file())
    prefix = out_dir / f"{PREFIX}{os.getpid()}-"  # same file system as the targets
    made: list[Path] = []  # folders created, deepest first
    copied: list[tuple[Path, Path]] = []  # (partial, target)
    placed: list[tuple[Path, Path | None]] = []  # (target, the file it replaced, kept aside)
    target = out_dir
    try:
        for number, item in enumerate(files):
            target = out_dir / item.relative_to(stage)
            made[:0] = [p for p in _new_folders(target.parent, out_dir)]
            target.parent.mkdir(parents=True, exist_ok=True)
            partial = Path(f"{prefix}{number}.part")
            copied.append((partial, target))
            shutil.copyfile(item, partial)
        for number, (partial, target) in enumerate(copied):
            if target.is_dir() and not target.is_symlink():  # only files are set aside
                raise IsADirectoryError(errno.EISDIR, "a folder is in the way", str(target))
            aside = Path(f"{prefix}{number}.old") if target.exists() else None
            if aside is not None:
                os.replace(target, aside)
            placed.append((target, aside))
            os.replace(partial, target)
    except BaseException as exc:
        _undo(copied, placed, made)
        if isinstance(exc, OSError):  # named by the target, never the staged or partial copy
            raise SimkitError(f"{target}: cannot write: {exc.strerror or exc}") from None
        raise
    for _, aside in placed:
        if aside is not None:
            aside.unlink(missing_ok=True)


def _new_folders(folder: Path, out_dir: Path) -> list[Path]:
    """The folders between `out_dir` and `folder` that do not exist yet, deepest first."""
    out = []
    while folder != out_dir and not folder.exists():
        out.append(folder)
        folder = folder.parent
    return out


def _undo(copied: list, placed: list, made: list[Path]) -> None:
    """Put back what `publish` replaced, remove what it added (renames only: no space)."""
    for target, aside in reversed(placed):
        if aside is not None and aside.exists():
            os.replace(aside, target)
        elif aside is None:
            target.unlink(missing_ok=True)
    for partial, _ in copied:
        partial.unlink(missing_ok=True)
    for folder in made:
        with contextlib.suppress(OSError):
            folder.rmdir()
