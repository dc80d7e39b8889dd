"""Paths that come from data simkit did not write itself (cache entries, other machines'
results) stay inside their destination folder (issue 24, "Cache trust").

A stored path is relative POSIX text: not empty, not absolute, no drive, no backslash or
NUL, no empty, `.` or `..` part. Writing resolves every target and refuses one that leaves
the destination or passes through a symbolic link, and never follows a link at the file
itself (kitio/reuse.py writes with O_EXCL), so a forged entry cannot write outside `--out`.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from simkit.errors import SimkitError


class UnsafePath(SimkitError, ValueError):
    """A stored path that would leave its destination folder."""


def check_relative(rel: object) -> tuple[str, ...]:
    """The parts of a safe relative POSIX path; UnsafePath otherwise."""
    if not isinstance(rel, str) or not rel:
        raise UnsafePath(f"{rel!r}: a stored path must be non-empty text")
    if "\\" in rel or "\0" in rel or rel.startswith("/") or ":" in rel.split("/", 1)[0]:
        raise UnsafePath(f"{rel!r}: absolute, drive or backslash path refused")
    parts = tuple(rel.split("/"))
    if any(part in ("", ".", "..") for part in parts):
        raise UnsafePath(f"{rel!r}: empty, '.' or '..' path part refused")
    return parts


def check_tree(paths: Iterable[object]) -> None:
    """Every path safe, and none is also a folder of another (`a` and `a/b`)."""
    seen = [check_relative(p) for p in paths]
    files = set(seen)
    for parts in seen:
        for i in range(1, len(parts)):
            if parts[:i] in files:
                raise UnsafePath(f"{'/'.join(parts[:i])!r}: both a file and a folder")


def confined(root: Path, rel: str) -> Path:
    """`root/rel`, refused when it leaves `root` once resolved or crosses a link below it."""
    parts = check_relative(rel)
    base = root.resolve()
    target = base.joinpath(*parts)
    walk = base
    for part in parts:
        walk = walk / part
        if walk.is_symlink():
            raise UnsafePath(f"{rel!r}: passes through a symbolic link under {root}")
    if not target.resolve().is_relative_to(base):
        raise UnsafePath(f"{rel!r}: resolves outside {root}")
    return target
