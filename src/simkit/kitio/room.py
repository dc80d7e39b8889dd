"""Fail fast: before a build derives anything, `--out` must be a folder it can write and its
disk must hold a kit (issue 38). Both are found in seconds otherwise, after derive and emit.

How much room: the kit folder, zip and manifest the last build of this kit left in `--out`
(a rebuild stages at most that much again, for a kit of about the same size; unchanged files
are hard links and cost nothing), else `FIRST_BUILD_BYTES` for a first build. The free figure
is `shutil.disk_usage` of `--out` (or of its nearest existing parent, so nothing is created
before the check passes); `FREE_ENV` replaces it in tests. Standard library only.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from simkit.errors import SimkitError
from simkit.kitio import atomic, fmt, layout, manifest

#: A first build's estimate, in bytes: about five times the seed kits (each about 3 MB: kit
#: folder and zip) for kits with larger meshes; imported CAD meshes can need more.
FIRST_BUILD_BYTES = 16 * 1024 * 1024
#: Test seam: a decimal number of bytes that replaces the disk's free space.
FREE_ENV = "SIMKIT_TEST_FREE_BYTES"


def _existing(path: Path) -> Path:
    """`path`, or its nearest parent that exists (a file in the way is refused later)."""
    path = Path(os.path.abspath(path))
    while not path.exists() and path != path.parent:
        path = path.parent
    return path


def free_bytes(path: Path) -> int:
    """Free bytes on the disk holding `path` (`shutil.disk_usage`; `FREE_ENV` in tests)."""
    given = os.environ.get(FREE_ENV)
    if given is not None:
        return int(given)
    return shutil.disk_usage(_existing(path)).free


def last_kit_bytes(out_dir: Path, robot: str) -> int | None:
    """Bytes of `robot`'s kit folder, zip and manifest published in `out_dir`, or None when
    there is none."""
    kit = out_dir / layout.kit_dir_name(robot)
    paths = list(manifest.tree(kit).values()) if kit.is_dir() else []
    paths += [out_dir / layout.zip_name(robot), out_dir / manifest.name(robot)]
    sizes = [p.stat().st_size for p in paths if p.is_file() and not p.is_symlink()]
    return sum(sizes) if sizes else None


def _mb(n: int) -> str:
    return f"{fmt.num(n / 1e6, 3)} MB"


def check_room(out_dir: Path, robot: str, free: int | None = None) -> None:
    """Raise one line when the disk of `out_dir` holds less than the kit needs. `free`:
    the free bytes (default: `free_bytes`)."""
    last = last_kit_bytes(out_dir, robot)
    need = FIRST_BUILD_BYTES if last is None else last
    have = free_bytes(out_dir) if free is None else free
    if have >= need:
        return
    what = (
        f"a first build needs about {_mb(need)} (an estimate)"
        if last is None
        else f"the last {robot} kit there took {_mb(need)} (folder, zip and manifest)"
    )
    raise SimkitError(
        f"{out_dir}: not enough free disk space for the kit: {_mb(have)} free, {what}; "
        "free some space or give --out a folder on another disk"
    )


def preflight(out_dir: Path, robot: str) -> None:
    """Both checks, before any derive work: the disk's room (nothing created yet), then
    `--out` created and writable (`atomic.writable`); each failure is one line."""
    target = _existing(out_dir)
    if target.exists() and not target.is_dir():
        atomic.writable(out_dir)  # the one-line refusal of a file in the way
    check_room(out_dir, robot)
    atomic.writable(out_dir)
