"""Run one slow, independent piece of work in a forked child while the caller does the rest.

Why: a cold STEP kit pays for the Open CASCADE import (about 0.8 s) and the B-rep solids
twice over, once to write the STEP and once to check it (issue 14), while the rest of the
emit and check stages runs on one core. A forked child does that work on a second core. A
fork, not a spawn: the child inherits the imported simkit and the model, so it pays only for
its own work (a spawned worker re-imports simkit, which cost more than it saved).

Better still, `warm_worker` forks one child at the start of a cold build that imports Open
CASCADE while the derive stage runs, then takes the STEP jobs (pickled) as they come.

The child's result comes back pickled through a pipe. Where there is no `os.fork`, where
`SIMKIT_NO_FORK=1`, or where the child ends without a result (an exception, a signal), the
work runs in-process when its result is asked for: the same deterministic function, so the
bytes are the same and an error surfaces exactly as it would without the fork.

Children take the default signal dispositions (`interrupt.in_child`; signals are blocked
across the fork so none reaches a child still holding the parent's handler): a signal ends
a child at once. When the parent is interrupted (SIGTERM, SIGINT), its `finally` blocks
(`run_all`, `warm_worker`) kill and reap every child, so none outlives it.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import pickle
import signal
import struct
import warnings
from collections.abc import Callable, Iterator
from typing import BinaryIO, Generic, TypeVar

from simkit.kitio import interrupt

T = TypeVar("T")


def _can_fork() -> bool:
    """Fork only where it is safe: not where JAX is loaded (its thread pool can deadlock a
    forked child; MJX users import it, simkit itself never does)."""
    import sys

    return (
        hasattr(os, "fork")
        and os.environ.get("SIMKIT_NO_FORK", "") not in ("1", "true")
        and "jax" not in sys.modules
    )


class Background(Generic[T]):
    """`work()` started in a forked child; `result()` waits for it (or runs it here)."""

    def __init__(self, work: Callable[[], T]) -> None:
        self._work = work
        self._pid = 0
        self._read_fd = -1
        self._worker: Worker | None = None
        if _WORKER is not None and _WORKER.send(work):
            self._worker = _WORKER  # the warm child already imported what `work` needs
        elif _can_fork():
            self._fork()

    def _fork(self) -> None:
        read_fd, write_fd = os.pipe()
        with warnings.catch_warnings():
            # Python 3.12+ warns on fork in a process with threads. Ours are idle BLAS pools;
            # the child runs only `work` and leaves with os._exit, never through Python exit.
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = _fork()
        if pid == 0:  # the child
            os.close(read_fd)
            _child(self._work, write_fd)
        os.close(write_fd)
        self._pid, self._read_fd = pid, read_fd

    def result(self) -> T:
        """The work's value: the child's, else computed here."""
        if self._worker is not None:
            reply, self._worker = self._worker.receive(), None
            if reply is not None and reply[0] == "ok":
                return reply[1]
            return self._work()
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
        if self._worker is not None:  # its reply would come first to the next job: stop it
            self._worker.close()
            self._worker = None
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


def _fork() -> int:
    """`os.fork` with the interrupting signals blocked across it; the child takes the
    default dispositions before they are unblocked (see the module docstring)."""
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, interrupt.SIGNALS)
    try:
        pid = os.fork()
        if pid == 0:
            interrupt.in_child()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
    return pid


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


def run_all(jobs: dict[str, Callable[[], T]], beside: tuple[str, ...]) -> dict[str, T]:
    """Every job's value, by name (in `jobs` order). The jobs named in `beside` start first as
    `Background` work (keep them picklable, e.g. a `functools.partial` of module functions,
    so the warm worker can take them); the rest run here meanwhile."""
    background = {name: Background(jobs[name]) for name in beside if name in jobs}
    try:
        done = {name: job() for name, job in jobs.items() if name not in background}
        done.update({name: job.result() for name, job in background.items()})
    finally:
        for job in background.values():
            job.close()
    return {name: done[name] for name in jobs}


#: The warm worker `Background` sends its work to while one is running (`warm_worker`).
_WORKER: Worker | None = None


@contextlib.contextmanager
def warm_worker(modules: tuple[str, ...]) -> Iterator[None]:
    """Within the block, `Background` work goes to one forked child that imported `modules`
    as soon as the block began (e.g. Open CASCADE, 0.8 s, while the derive stage runs)."""
    global _WORKER
    worker = Worker(modules) if modules and _can_fork() else None
    previous, _WORKER = _WORKER, worker
    try:
        yield
    finally:
        _WORKER = previous
        if worker is not None:
            worker.close()


class Worker:
    """A forked child that imports `modules` at once, then runs the pickled jobs it is sent,
    one at a time, and sends back ("ok", value) or ("failed", None) for each."""

    def __init__(self, modules: tuple[str, ...]) -> None:
        self.pid, self.pending = 0, False
        job_read, job_write = os.pipe()
        result_read, result_write = os.pipe()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # see Background._fork
            pid = _fork()
        if pid == 0:
            os.close(job_write)
            os.close(result_read)
            _serve(modules, job_read, result_write)
        os.close(job_read)
        os.close(result_write)
        self.pid = pid
        self._jobs = os.fdopen(job_write, "wb")
        self._results = os.fdopen(result_read, "rb")

    def send(self, work: Callable[[], object]) -> bool:
        """Queue `work`; False when it cannot go (busy, gone, or not picklable)."""
        if not self.pid or self.pending:
            return False
        try:
            data = pickle.dumps(work)
            _write_frame(self._jobs, data)
        except Exception:  # unpicklable work, or a dead worker: the caller forks instead
            return False
        self.pending = True
        return True

    def receive(self) -> tuple[str, object] | None:
        """The reply to the job sent last, or None when the worker died."""
        self.pending = False
        try:
            frame = _read_frame(self._results)
            return pickle.loads(frame) if frame is not None else None
        except Exception:  # a dead worker or a garbled reply: the caller runs the work
            return None

    def close(self) -> None:
        """Stop the worker (it may be importing or running a job) and reap it."""
        for pipe in (self._jobs, self._results):
            with contextlib.suppress(OSError):
                pipe.close()
        if self.pid:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, 9)
            with contextlib.suppress(ChildProcessError):
                os.waitpid(self.pid, 0)
            self.pid = 0


def _serve(modules: tuple[str, ...], job_fd: int, result_fd: int) -> None:
    """The worker's loop: import, then answer each job until the parent closes the pipe."""
    try:
        for name in modules:
            with contextlib.suppress(ImportError):
                importlib.import_module(name)
        jobs, results = os.fdopen(job_fd, "rb"), os.fdopen(result_fd, "wb")
        while (frame := _read_frame(jobs)) is not None:
            try:
                payload = pickle.dumps(("ok", pickle.loads(frame)()))
            except BaseException:  # the parent reruns the work in-process and reports it
                payload = pickle.dumps(("failed", None))
            _write_frame(results, payload)
    finally:
        os._exit(0)


def _write_frame(pipe: BinaryIO, data: bytes) -> None:
    pipe.write(struct.pack("<Q", len(data)) + data)
    pipe.flush()


def _read_frame(pipe: BinaryIO) -> bytes | None:
    head = pipe.read(8)
    if len(head) < 8:
        return None
    size = struct.unpack("<Q", head)[0]
    data = pipe.read(size)
    return data if len(data) == size else None  # a writer that died mid-frame
