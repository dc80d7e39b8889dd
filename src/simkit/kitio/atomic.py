"""Crash-safe publishing of a kit folder and its zip as real folder and file in `--out`.

    out/NAME_description/         the kit, a plain folder
    out/NAME-sim-kit.zip          its zip, a plain file
    out/.NAME.manifest.json       hidden: both digests (`manifest.py`)

A build writes the kit, the zip and the new manifest into a staging folder
`.NAME.<id>.staging` beside them and checks them there; unchanged files are hard links to the
published ones (`reuse.py`). When nothing differs, nothing is published: no byte, name or
mtime under `--out` changes. Otherwise the staging folder is renamed to the journal
`.NAME.commit` and rolled forward, each step idempotent:

1. the staged kit folder and the published one are exchanged by one
   `renameat2(RENAME_EXCHANGE)` (Linux); the journal records the staged folder's inode, so a
   rerun knows whether this happened;
2. the zip, then the manifest, are renamed over the published ones (`rename(2)`);
3. the journal (now holding the old kit) is renamed to `.NAME.<id>.trash` and removed.

A kill -9 at any instant leaves a kit and a zip of one build, except between steps 1 and 2
(the new kit beside the old zip): there the journal is still present, `simkit check` reports
the mismatch, and the next build into the folder says so on one line and finishes the
publish (`repair`). Without renameat2 (macOS, other filesystems) step 1 is two renames, the
old kit moved into the journal and the new one into place; a kill between them leaves no kit
folder until the next build finishes the publish. A kit folder left as a symlink by an
earlier simkit (`.NAME.current` generations) is replaced by the same exchange.

SIGTERM, SIGINT or SIGHUP (`kitio/interrupt.py`) arriving once the journal is written take
effect when the publish is complete: the section from the journal to `cleaned` is `held`.
Before it, the staging folder is removed and the published kit is untouched.

Builds into one folder serialize on an `flock` of the folder itself (no lock file). Test
hooks: `SIMKIT_TEST_KILL_AT=<step>` kills the process with SIGKILL at that step;
`SIMKIT_TEST_SIGNAL_AT=<step>` sends it SIGTERM there.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import signal
import tempfile
from collections.abc import Iterator
from pathlib import Path

from simkit.errors import SimkitError
from simkit.kitio import interrupt, layout, manifest, reuse

KILL_ENV = "SIMKIT_TEST_KILL_AT"
SIGNAL_ENV = "SIMKIT_TEST_SIGNAL_AT"
#: The publishing steps, in order, at which the test hook can kill a build.
STEPS = (
    "locked",
    "staged",
    "journaled",
    "kit_aside",  # only without renameat2
    "kit_swapped",
    "zip_moved",
    "manifest_moved",
    "journal_closed",
    "cleaned",
)
#: The steps of `swap_folder` (simkit publish's site folder) at which the hook can kill.
FOLDER_STEPS = ("site_staged", "site_moved_aside", "site_swapped")
_INODE = "kit.inode"
_OLD_KIT = "old_kit"


def step(name: str) -> None:
    """Test hooks: die here (SIGKILL, no cleanup) when `SIMKIT_TEST_KILL_AT` names this step;
    send SIGTERM (the normal clean-up) when `SIMKIT_TEST_SIGNAL_AT` does."""
    if os.environ.get(KILL_ENV) == name:
        os.kill(os.getpid(), signal.SIGKILL)
    if os.environ.get(SIGNAL_ENV) == name:
        os.kill(os.getpid(), signal.SIGTERM)


def writable(out_dir: Path) -> None:
    """Create `out_dir`; any failure is one line naming it and saying what to do (a file in
    the way, no permission, ...)."""
    fix = "give --out a folder you can write to"
    if out_dir.exists() and not out_dir.is_dir():
        raise SimkitError(f"{out_dir}: --out is a file, not a folder; {fix}")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SimkitError(
            f"{out_dir}: cannot create the output folder: {exc.strerror}; {fix}"
        ) from None
    if not os.access(out_dir, os.W_OK | os.X_OK):
        raise SimkitError(f"{out_dir}: the output folder is not writable; {fix}")


def acquire(out_dir: Path, shared: bool = False) -> int:
    """Take an `flock` on `out_dir` (exclusive; `shared` for readers that write nothing),
    waiting for another build into it to finish. Returns the fd for `release`."""
    import fcntl

    if not shared:
        writable(out_dir)
    fd = os.open(out_dir, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_SH if shared else fcntl.LOCK_EX)
        step("locked")
    except BaseException:
        os.close(fd)
        raise
    return fd


def release(fd: int) -> None:
    """Drop the lock `acquire` took (closing the folder's fd releases it)."""
    os.close(fd)


@contextlib.contextmanager
def locked(out_dir: Path) -> Iterator[None]:
    """`acquire` ... `release` as a context manager."""
    fd = acquire(out_dir)
    try:
        yield
    finally:
        release(fd)


def _visible(out_dir: Path, robot: str) -> tuple[Path, Path, Path]:
    """(kit folder, zip, manifest) as published in `out_dir`."""
    return (
        out_dir / layout.kit_dir_name(robot),
        out_dir / layout.zip_name(robot),
        out_dir / manifest.name(robot),
    )


def _remove(path: Path) -> None:
    if path.is_symlink() or path.is_file():
        path.unlink(missing_ok=True)
    elif path.is_dir():
        shutil.rmtree(path, ignore_errors=True)


def staging(out_dir: Path, robot: str) -> Path:
    """A fresh staging folder for `robot` beside the output (its kit folder is published as
    it is, so it is readable as any folder)."""
    path = Path(tempfile.mkdtemp(prefix=f".{robot}.", suffix=".staging", dir=out_dir))
    path.chmod(0o755)
    return path


@contextlib.contextmanager
def staging_area(out_dir: Path, robot: str) -> Iterator[Path]:
    """`staging`, removed on exit. When nothing was published from it (`commit` renames it,
    so it is gone then), `out_dir` gets back its mtime: a build that changed nothing, or
    failed, leaves no trace there."""
    st = out_dir.stat()
    path = None
    try:
        with interrupt.held():  # a signal right after mkdir still finds `path` set
            path = staging(out_dir, robot)
        yield path
    finally:
        published = path is not None and not path.exists()
        if path is not None:
            _remove(path)
        if not published:
            os.utime(out_dir, ns=(st.st_atime_ns, st.st_mtime_ns))


def stage_kit(staged: Path, out_dir: Path, robot: str, files: dict[str, bytes]) -> int:
    """Write kit `files` into `staged`, hard-linking the published kit's unchanged files;
    returns how many were reused."""
    kit = _visible(out_dir, robot)[0]
    return reuse.write_tree(staged / kit.name, files, kit)


def stage_file(staged: Path, out_dir: Path, name: str, data: bytes) -> None:
    """Write the zip or the manifest (`name`, as published in `out_dir`) into `staged`,
    hard-linking the published one when unchanged."""
    reuse.write_file(staged / name, data, out_dir / name)


def _exchange(a: Path, b: Path) -> bool:
    """Atomically swap paths `a` and `b` (Linux renameat2 RENAME_EXCHANGE); False if the
    system cannot."""
    import ctypes
    import errno

    libc = ctypes.CDLL(None, use_errno=True)
    fn = getattr(libc, "renameat2", None)
    if fn is None:
        return False
    at_fdcwd, rename_exchange = -100, 2
    if fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(code, os.strerror(code), str(a))


def _unchanged(staged: Path, out_dir: Path, robot: str) -> bool:
    """The staged kit, zip and manifest equal the published ones, byte for byte."""
    kit, *single = _visible(out_dir, robot)
    if not reuse.same_tree(staged / kit.name, kit):
        return False
    return all(
        not path.is_symlink() and reuse.same_bytes(path, (staged / path.name).read_bytes())
        for path in single
    )


def commit(staged: Path, out_dir: Path, robot: str) -> bool:
    """Publish the checked kit, zip and manifest in `staged` (call with the lock held).
    Returns False when they equal the published ones: then nothing is written."""
    step("staged")
    kit, _, _ = _visible(out_dir, robot)
    if _unchanged(staged, out_dir, robot):
        return False
    if kit.is_dir() and not kit.is_symlink():
        reuse.keep_folder_times(staged / kit.name, kit)
    (staged / _INODE).write_text(str((staged / kit.name).stat().st_ino))
    with interrupt.held():  # once journaled, a signal waits for the publish to complete
        os.rename(staged, out_dir / manifest.journal_name(robot))
        step("journaled")
        _roll_forward(out_dir, robot)
        clean(out_dir, robot)
        step("cleaned")
    return True


def _roll_forward(out_dir: Path, robot: str) -> bool:
    """Finish the publish the journal `.NAME.commit` describes; every step checks whether it
    already happened, so a rerun after a kill at any instant completes it. False when the
    journal is damaged (its kit is gone): it is dropped, and the next commit republishes."""
    journal = out_dir / manifest.journal_name(robot)
    kit, zip_path, manifest_path = _visible(out_dir, robot)
    try:
        inode = int((journal / _INODE).read_text())
    except (OSError, ValueError):
        inode = -1
    new = journal / kit.name
    done = kit.is_dir() and not kit.is_symlink() and kit.stat().st_ino == inode
    whole = done or (new.is_dir() and not new.is_symlink() and new.stat().st_ino == inode)
    if whole and not done:
        if not (kit.exists() or kit.is_symlink()):
            os.rename(new, kit)  # a first build, or a kill between the two renames below
        elif not _exchange(new, kit):
            os.rename(kit, journal / _OLD_KIT)
            step("kit_aside")
            os.rename(new, kit)
        step("kit_swapped")
    for published, name in ((zip_path, "zip_moved"), (manifest_path, "manifest_moved")):
        if whole and (journal / published.name).exists():
            os.replace(journal / published.name, published)
            step(name)
    os.rename(journal, out_dir / f".{robot}.{secrets.token_hex(4)}.trash")
    step("journal_closed")
    return whole


def repair(out_dir: Path, robot: str) -> str | None:
    """Finish a publish a killed build left (call with the lock held) and remove what it
    left; returns one line saying so, or None when there was none."""
    journal = out_dir / manifest.journal_name(robot)
    said = None
    if journal.is_dir() and not journal.is_symlink():
        kit = out_dir / layout.kit_dir_name(robot)
        said = (
            f"{kit}: the previous build was killed while publishing the kit and its zip "
            "(they may come from different builds); "
            + ("finished publishing it" if _roll_forward(out_dir, robot) else "republishing")
        )
    elif journal.is_symlink() or journal.exists():
        _remove(journal)
    clean(out_dir, robot)
    return said


def leftovers(out_dir: Path, robot: str) -> list[Path]:
    """The staging, trash and temporary entries an interrupted build of `robot` left in
    `out_dir` (`.NAME.<id>.staging`, `.NAME.<id>.trash`, `.NAME.<id>.tmp`): simkit's own names
    for this kit only, never another kit's or a user's file."""
    suffixes = (".staging", ".trash", ".tmp")
    return [p for p in sorted(out_dir.glob(f".{robot}.*")) if p.name.endswith(suffixes)]


def clean(out_dir: Path, robot: str) -> None:
    """Remove what an interrupted build of `robot` left (call with the lock held): staging
    and trash folders and, once the kit is a plain folder, an earlier simkit's generations."""
    for path in leftovers(out_dir, robot):
        _remove(path)
    kit, zip_path, _ = _visible(out_dir, robot)
    if kit.is_symlink() or zip_path.is_symlink():
        return  # still the generation layout: its links point into .NAME.current
    legacy = [out_dir / f".{robot}.current", out_dir / f".{robot}.legacy"]
    legacy += sorted(out_dir.glob(f".{robot}.*.gen"))
    legacy += [out_dir / f".{kit.name}.old", out_dir / f".{zip_path.name}.old"]
    for path in legacy:
        _remove(path)


def recover_folder(final: Path) -> None:
    """Before replacing folder `final` (call with `final.parent` locked): put back the old
    folder a kill left aside (no renameat2), and remove stale `.NAME.*.staging` folders."""
    old = final.with_name(f".{final.name}.old")
    if old.is_dir() and not final.exists():
        os.rename(old, final)
    _remove(old)
    for path in sorted(final.parent.glob(f".{final.name}.*.staging")):
        _remove(path)


def swap_folder(staged: Path, final: Path) -> None:
    """Replace folder `final` by `staged` (call with `final.parent` locked). With renameat2
    the two are exchanged in one step and the old one removed, so a kill at any instant
    leaves the old folder or the new one, whole. Without it, the old folder is moved aside
    first and `recover_folder` puts it back if a kill comes between the two renames."""
    step("site_staged")
    with interrupt.held():  # a signal waits for the swap to complete
        if not final.exists():
            os.rename(staged, final)
        elif _exchange(staged, final):
            step("site_swapped")
            _remove(staged)  # now the old folder
        else:
            old = final.with_name(f".{final.name}.old")
            _remove(old)
            os.rename(final, old)
            step("site_moved_aside")
            os.rename(staged, final)
            step("site_swapped")
            _remove(old)
