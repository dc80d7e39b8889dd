"""SIGTERM, SIGINT and SIGHUP end a command through its normal clean-up.

Python's default SIGTERM (and SIGHUP) kill the process at once: no `finally` runs, so a
build's staging folder, a publish's site folder and an import's `.import-*` folder stay
behind, and forked workers may outlive it. `installed()` (the CLI entry)
turns each of them into `Interrupted`, a `SystemExit` with the conventional code (128 + the
signal: 130 for SIGINT, 143 for SIGTERM). Not `KeyboardInterrupt` for SIGINT: a
KeyboardInterrupt that passes through code a C extension runs with `PyRun_String`
(pybind11's `exec`, while a library is imported) marks the interpreter, which then kills
itself with SIGINT at exit (status -2) even after simkit handled it. Code that stops on
Ctrl-C (`simkit view`) catches `Interrupted` with `signum == SIGINT`. Every `finally` and
context manager runs: staging folders are removed, locks released, forked children stopped
and reaped. Further signals are ignored from then on, so the clean-up is not cut short.

`held()` marks a section that must finish once begun (publishing a kit's folder, zip and
manifest): a signal that arrives inside it takes effect when the section ends. The Python
handler always runs in the main thread, so this holds whichever thread the kernel picked.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator

#: The signals that end a command through its clean-up.
SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)

_depth = 0  # how many `held` sections are open
_pending: int | None = None  # a signal that arrived inside one


class Interrupted(SystemExit):
    """A signal ended the command; `code` is 128 + the signal number."""

    def __init__(self, signum: int) -> None:
        super().__init__(128 + signum)
        self.signum = signum

    def line(self) -> str:
        """The one line the CLI prints once the clean-up is done."""
        name = signal.Signals(self.signum).name
        return f"interrupted by {name}; temporary files removed"


def _handler(signum: int, _frame: object) -> None:
    global _pending
    if _depth:
        _pending = signum
        return
    _interrupt(signum)


def ignore() -> None:
    """Ignore `SIGNALS` from now on (main thread only): a signal that arrives again, or
    late, cannot cut a clean-up or an exit short."""
    if threading.current_thread() is threading.main_thread():
        for sig in SIGNALS:
            signal.signal(sig, signal.SIG_IGN)


def _interrupt(signum: int) -> None:
    """Ignore further signals, stop pool workers, and raise `Interrupted`."""
    ignore()
    _stop_pool_workers()
    raise Interrupted(signum)


def _stop_pool_workers() -> None:
    """End multiprocessing workers (e.g. the CoACD pool): a pool's shutdown would wait for
    their running jobs. Forked `kitio.forked` children are stopped by their own `finally`."""
    if "multiprocessing" not in sys.modules:
        return
    import multiprocessing

    for child in multiprocessing.active_children():
        with contextlib.suppress(OSError):
            child.kill()


@contextlib.contextmanager
def installed() -> Iterator[None]:
    """Within the block, `SIGNALS` raise `Interrupted`; the previous handlers come back
    after it. Only the main thread can set handlers: elsewhere this does nothing."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, _handler) for sig in SIGNALS}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


@contextlib.contextmanager
def held() -> Iterator[None]:
    """A section that finishes once begun: a signal inside it takes effect at its end."""
    global _depth, _pending
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        if not _depth and _pending is not None:
            signum, _pending = _pending, None
            _interrupt(signum)


def in_child() -> None:
    """In a forked child: the default dispositions (a signal ends it at once; the parent
    reruns or drops its work), and no `held` state inherited from the parent."""
    global _depth, _pending
    _depth, _pending = 0, None
    for sig in SIGNALS:
        if signal.getsignal(sig) is _handler:
            signal.signal(sig, signal.SIG_DFL)
