"""Run one slow, independent piece of work in a forked child while the caller does the rest.

Why: a cold STEP kit pays for the Open CASCADE import (about 0.8 s) and the B-rep solids
twice over, once to write the STEP and once to check it (issue 14), while the rest of the
emit and check stages runs on one core. A forked child does that work on a second core. A
fork, not a spawn: the child inherits the imported simkit and the model, so it pays only for
its own work (a spawned worker re-imports simkit, which cost more than it saved).

The child's result comes back pickled through a pipe. Where there is no `os.fork`, where
`SIMKIT_NO_FORK=1`, or where the child ends without a result (an exception, a signal), the
work runs in-process when its result is asked for: the same deterministic function, so the
bytes are the same and an error surfaces exactly as it would without the fork.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import warnings
from collections.abc import Callable
from typing import Generic, TypeVar

T = TypeVar("T")


def _can_fork() -> bool:
    return hasattr(os, "fork") and os.environ.get("SIMKIT_NO_FORK", "") not in ("1", "true")


class Background(Generic[T]):
    """`work()` started in a forked child; `result()` waits for it (or runs it here)."""

    def __init__(self, work: Callable[[], T]) -> None:
        self._work = work
        self._pid = 0
        self._read_fd = -1
        if _can_fork():
            self._fork()

    def _fork(self) -> None:
        read_fd, write_fd = os.pipe()
        with warnings.catch_warnings():
            # Python 3.12+ warns on fork in a process with threads. Ours are idle BLAS pools;
            # the child runs only `work` and leaves with os._exit, never through Python exit.
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
        if pid == 0:  # the child
            os.close(read_fd)
            _child(self._work, write_fd)
        os.close(write_fd)
        self._pid, self._read_fd = pid, read_fd

    def result(self) -> T:
        """The work's value: the child's, else computed here."""
        if self._pid:
            with os.fdopen(self._read_fd, "rb") as pipe:
                payload = pipe.read()
            self._read_fd = -1
            self._reap()
            if payload:
                status, value = pickle.loads(payload)
                if status == "ok":
                    return value
        return self._work()

    def close(self) -> None:
        """Stop and reap a child whose result is no longer wanted (the caller failed)."""
        if self._read_fd >= 0:
            os.close(self._read_fd)
            self._read_fd = -1
        if self._pid:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self._pid, 9)
            self._reap()

    def _reap(self) -> None:
        with contextlib.suppress(ChildProcessError):
            os.waitpid(self._pid, 0)
        self._pid = 0


def _child(work: Callable[[], object], write_fd: int) -> None:
    """Run `work`, send ("ok", value) or ("failed", None) and leave without Python's exit
    handlers (they belong to the parent)."""
    try:
        try:
            payload = pickle.dumps(("ok", work()))
        except BaseException:  # the parent reruns the work in-process and reports it there
            payload = pickle.dumps(("failed", None))
        with os.fdopen(write_fd, "wb") as pipe:
            pipe.write(payload)
    finally:
        os._exit(0)
