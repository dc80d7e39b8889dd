"""What every `simkit` command shares: the two consoles and the one-line error exit."""

from __future__ import annotations

import sys
from typing import NoReturn

from rich.console import Console

from simkit.errors import SimkitError

err = Console(stderr=True, highlight=False, soft_wrap=True)
out = Console(highlight=False, soft_wrap=True)
RAY_HELP = "One Ray task per robot ($RAY_ADDRESS, else a local Ray); needs simkit[ray]."


def fail(exc: SimkitError) -> NoReturn:
    """Print `exc` as one line on stderr and exit with its code (no traceback for users)."""
    err.print(f"simkit: error: {exc}", markup=False)
    sys.exit(exc.exit_code)


def say(msg: str) -> None:
    """Progress for the library's `say`/`progress` callbacks: stderr, so stdout stays data."""
    err.print(msg, markup=False)
