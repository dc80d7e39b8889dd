"""Crash-consistent publishing of a kit folder and its zip, as one unit.

A build writes the kit and the zip into a staging folder `.NAME.<id>.staging` beside the
output, checks them there, and publishes them with one atomic step:

    out/NAME_description    -> .NAME.current/NAME_description   (fixed symlinks)
    out/NAME-sim-kit.zip    -> .NAME.current/NAME-sim-kit.zip
    out/.NAME.current       -> .NAME.<id>.gen                   (switched by one rename)
    out/.NAME.<id>.gen/     NAME_description/ and NAME-sim-kit.zip of one build

Switching `.NAME.current` is a single `rename(2)` of a new symlink over the old one, so
after a kill -9 at any instant the visible kit and zip are those of one and the same build,
the old one or the new one. Whatever a kill leaves behind (staging folders, unused
generations, temporary links, the `.old` folders of simkit's earlier swap) the next build
into the folder removes. A kit folder and zip written by an earlier simkit (plain folder
and file) are moved into a generation first; the folder is exchanged for its symlink with
`renameat2(RENAME_EXCHANGE)`, so that step is atomic too.

Builds into one output folder serialize on an `flock` of the folder itself (no lock file).
Test hook: `SIMKIT_TEST_KILL_AT=<step>` kills the process with SIGKILL at that step.
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
from simkit.kitio import layout

KILL_ENV = "SIMKIT_TEST_KILL_AT"
#: The publishing steps, in order, at which the test hook can kill a build.
STEPS = (
    "locked",
    "staged",
    "legacy_copied",
    "legacy_current",
    "legacy_zip",
    "legacy_kit",
    "generation",
    "switched",
    "linked",
    "cleaned",
)
#: The steps of `swap_folder` (simkit publish's site folder) at which the hook can kill.
FOLDER_STEPS = ("site_staged", "site_moved_aside", "site_swapped")


def step(name: str) -> None:
    """Test hook: die here (SIGKILL, no cleanup) when `SIMKIT_TEST_KILL_AT` names this step."""
    if os.environ.get(KILL_ENV) == name:
        os.kill(os.getpid(), signal.SIGKILL)


def _writable(out_dir: Path) -> None:
    """Create `out_dir`; any failure is one line (a file in the way, no permission, ...)."""
    if out_dir.exists() and not out_dir.is_dir():
        raise SimkitError(f"{out_dir}: --out is a file, not a folder")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SimkitError(f"{out_dir}: cannot create the output folder: {exc.strerror}") from None
    if not os.access(out_dir, os.W_OK | os.X_OK):
        raise SimkitError(f"{out_dir}: the output folder is not writable")


def acquire(out_dir: Path, robot: str | None = None) -> int:
    """Take an exclusive `flock` on `out_dir` (waits for another build into it to finish);
    with `robot`, then `repair` what a killed build of it left. Returns the fd for
    `release`."""
    import fcntl

    _writable(out_dir)
    fd = os.open(out_dir, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        step("locked")
        if robot is not None:
            repair(out_dir, robot)
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


def _current(out_dir: Path, robot: str) -> Path:
    return out_dir / f".{robot}.current"


def _visible(out_dir: Path, robot: str) -> tuple[Path, Path]:
    return out_dir / layout.kit_dir_name(robot), out_dir / layout.zip_name(robot)


def _remove(path: Path) -> None:
    if path.is_symlink() or path.is_file():
        path.unlink(missing_ok=True)
    elif path.is_dir():
        shutil.rmtree(path, ignore_errors=True)


def _live_generation(out_dir: Path, robot: str) -> str | None:
    link = _current(out_dir, robot)
    return os.readlink(link) if link.is_symlink() else None


def clean(out_dir: Path, robot: str) -> None:
    """Remove what an interrupted build of `robot` left (call with the lock held): staging
    folders, generations `.NAME.current` does not point to, temporary links, `.old` folders."""
    live = _live_generation(out_dir, robot)
    kit, zip_path = _visible(out_dir, robot)
    for path in sorted(out_dir.glob(f".{robot}.*")):
        name = path.name
        stale = (
            name.endswith((".staging", ".tmp"))
            or (name.endswith(".gen") and name != live)
            or name == f".{robot}.legacy"
        )
        if stale:
            _remove(path)
    for old in (f".{kit.name}.old", f".{zip_path.name}.old"):
        _remove(out_dir / old)


def staging(out_dir: Path, robot: str) -> Path:
    """A fresh staging folder for `robot` beside the output (readable as any folder: it
    becomes the published generation)."""
    path = Path(tempfile.mkdtemp(prefix=f".{robot}.", suffix=".staging", dir=out_dir))
    path.chmod(0o755)
    return path


def _link(out_dir: Path, robot: str, target: str, at: Path) -> None:
    """Point symlink `at` to `target` atomically (a temp link, which `clean` removes if a
    kill leaves it, renamed over it)."""
    tmp = out_dir / f".{robot}.{secrets.token_hex(4)}.tmp"
    os.symlink(target, tmp)
    os.replace(tmp, at)


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


def _adopt_legacy(out_dir: Path, robot: str) -> None:
    """Move a plain kit folder / zip (written before this scheme) into a generation, keeping
    what is visible unchanged at every instant."""
    kit, zip_path = _visible(out_dir, robot)
    plain = [p for p in (kit, zip_path) if p.exists() and not p.is_symlink()]
    if not plain:
        return
    if _live_generation(out_dir, robot) is None:
        gen = out_dir / f".{robot}.{secrets.token_hex(4)}.gen"
        tmp = out_dir / f".{robot}.legacy"
        _remove(tmp)
        tmp.mkdir()
        for path in plain:
            if path.is_dir():
                shutil.copytree(path, tmp / path.name, symlinks=True)
            else:
                shutil.copy2(path, tmp / path.name)
        step("legacy_copied")
        os.rename(tmp, gen)
        _link(out_dir, robot, gen.name, _current(out_dir, robot))
        step("legacy_current")
    current = _current(out_dir, robot).name
    if zip_path.exists() and not zip_path.is_symlink():
        _link(out_dir, robot, f"{current}/{zip_path.name}", zip_path)
        step("legacy_zip")
    if kit.exists() and not kit.is_symlink():
        tmp = out_dir / f".{robot}.{secrets.token_hex(4)}.tmp"
        os.symlink(f"{current}/{kit.name}", tmp)
        if not _exchange(tmp, kit):  # no renameat2: a short window without the folder
            os.rename(kit, out_dir / f".{robot}.{secrets.token_hex(4)}.staging")
            os.rename(tmp, kit)
        step("legacy_kit")
        _remove(tmp)


def commit(staged: Path, out_dir: Path, robot: str) -> None:
    """Publish the checked kit and zip in `staged` (call with the lock held)."""
    step("staged")
    _adopt_legacy(out_dir, robot)
    gen = staged.with_name(staged.name.removesuffix(".staging") + ".gen")
    os.rename(staged, gen)
    step("generation")
    _link(out_dir, robot, gen.name, _current(out_dir, robot))
    step("switched")
    current = _current(out_dir, robot).name
    for path in _visible(out_dir, robot):
        want = f"{current}/{path.name}"
        if not (path.is_symlink() and os.readlink(path) == want):
            _link(out_dir, robot, want, path)
    step("linked")
    clean(out_dir, robot)
    step("cleaned")


def repair(out_dir: Path, robot: str) -> None:
    """Finish what a killed build left (call with the lock held): the visible links of the
    live generation, then `clean`."""
    if _live_generation(out_dir, robot) is not None:
        current = _current(out_dir, robot).name
        for path in _visible(out_dir, robot):
            if not path.exists() and not path.is_symlink():
                _link(out_dir, robot, f"{current}/{path.name}", path)
    clean(out_dir, robot)


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
