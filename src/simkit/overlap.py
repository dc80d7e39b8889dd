"""Run one slow, self-contained job in a second process while this one carries on.

The STEP assembly costs about a second of Open CASCADE import plus its Boolean operations,
when it is written and again when it is checked. Both are independent of the other emitters
and checks, so `simkit build` runs them in a spawned worker next to the rest: on a machine
with two or more cores that hides most of the cost (docs/performance.md). Results are the
same as running in-process; only the wall time changes.
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Future
from typing import Any


class Overlap:
    """`with Overlap() as side: future = side.submit(fn, *args)`; the worker (spawned, so no
    state leaks from this process) starts on the first submit and stops on exit."""

    def __init__(self) -> None:
        self._pool = None

    def submit(self, fn: Callable[..., Any], *args: Any) -> Future:
        if self._pool is None:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            self._pool = ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"))
        return self._pool.submit(fn, *args)

    def __enter__(self) -> Overlap:
        return self

    def __exit__(self, *exc: object) -> None:
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
