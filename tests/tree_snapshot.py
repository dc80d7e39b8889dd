"""What a folder holds, for tests that a rebuild or a failed publish changed nothing."""

from __future__ import annotations

from pathlib import Path


def snapshot(out: Path) -> dict[str, tuple]:
    """Every entry under `out` (itself included): kind, bytes, inode and mtime."""
    seen = {}
    for path in [out, *sorted(out.rglob("*"))]:
        st = path.lstat()
        data = path.read_bytes() if path.is_file() else None
        seen[path.relative_to(out).as_posix()] = (st.st_mode, data, st.st_ino, st.st_mtime_ns)
    return seen
