"""Write a staged tree so that what did not change keeps its inode and modification time.

A rebuild stages every file anew, then swaps the staged folder in (`atomic.py`). A staged
file whose bytes equal the published file's is that file, hard-linked: after the swap it has
the same inode, bytes and mtime as before, so git, rsync and make see only real changes.
Where the filesystem has no hard links the bytes are written and the old mtime copied.
A staged folder whose entries are the published folder's keeps that folder's mtime too.
"""

from __future__ import annotations

import os
from pathlib import Path

from simkit.errors import SimkitError
from simkit.kitio import confine


def same_bytes(old: Path, data: bytes) -> bool:
    """`old` is a plain file holding exactly `data` (size first: most changes change it)."""
    try:
        if old.is_symlink() or not old.is_file() or old.stat().st_size != len(data):
            return False
        return old.read_bytes() == data
    except OSError:
        return False


def write_file(target: Path, data: bytes, old: Path | None = None) -> bool:
    """Create `target` holding `data`: a hard link to `old` when it holds the same bytes
    (True), else a new file (False). `target` must not exist: a linked inode is never
    written in place."""
    target.parent.mkdir(parents=True, exist_ok=True)
    if old is not None and same_bytes(old, data):
        try:
            os.link(old, target)
            return True
        except OSError:  # no hard links here: same bytes, old times
            target.write_bytes(data)
            st = old.stat()
            os.utime(target, ns=(st.st_atime_ns, st.st_mtime_ns))
            return True
    try:
        with open(target, "xb") as handle:
            handle.write(data)
    except OSError as exc:  # a full disk, a read-only folder: one line, no truncated file
        if target.is_file() and not target.is_symlink():
            target.unlink()
        raise SimkitError(f"{target}: cannot write: {exc.strerror}") from None
    return False


def write_tree(root: Path, files: dict[str, bytes], old_root: Path | None = None) -> int:
    """Write `files` (POSIX relative paths) under `root`, reusing `old_root`'s unchanged
    files; returns how many were reused. Every path is confined to `root` (kitio/confine.py:
    a forged cache entry cannot write outside the kit)."""
    confine.check_tree(files)
    reused = 0
    for rel, data in files.items():
        old = old_root.joinpath(*rel.split("/")) if old_root is not None else None
        reused += write_file(confine.confined(root, rel), data, old)
    return reused


def entries(root: Path) -> list[str]:
    """Every entry under `root` (files, folders, links), as sorted POSIX paths."""
    found = []
    for folder, dirs, names in os.walk(root):
        base = Path(folder).relative_to(root)
        found += [(base / entry).as_posix() for entry in (*dirs, *names)]
    return sorted(found)


def same_tree(new: Path, old: Path) -> bool:
    """Folders `new` and `old` hold the same entries and the same bytes in each file
    (hard links of each other are compared by inode only)."""
    if old.is_symlink() or not old.is_dir() or entries(new) != entries(old):
        return False
    for rel in entries(new):
        a, b = new / rel, old / rel
        if a.is_symlink() or b.is_symlink() or a.is_dir() != b.is_dir():
            return False
        if a.is_file() and not (os.path.samefile(a, b) or same_bytes(b, a.read_bytes())):
            return False
    return True


def keep_folder_times(root: Path, old_root: Path) -> None:
    """Give each folder under `root` (itself included) the mtime of its counterpart under
    `old_root` when both hold the same entry names (call after the last write into `root`)."""
    for folder, dirs, names in os.walk(root):
        new = Path(folder)
        old = old_root / new.relative_to(root)
        try:
            if old.is_symlink() or not old.is_dir():
                continue
            if sorted(os.listdir(old)) != sorted([*dirs, *names]):
                continue
            st = old.stat()
        except OSError:
            continue
        os.utime(new, ns=(st.st_atime_ns, st.st_mtime_ns))
