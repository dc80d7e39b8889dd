"""Where the packaged robots/ and templates/ live: inside the wheel (`simkit/_data/`) for a
normal install, or at the repository root for a source checkout or editable install."""

from __future__ import annotations

from functools import cache
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parents[1]  # the simkit package folder


@cache
def data_dir(name: str) -> Path:
    """`robots` or `templates` folder."""
    for candidate in (_PACKAGE / "_data" / name, _PACKAGE.parents[1] / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"simkit data folder '{name}' is missing from this installation")


def robot_names() -> list[str]:
    """Names of the packaged robot specs, sorted."""
    return sorted(p.stem for p in data_dir("robots").glob("*.yaml"))
