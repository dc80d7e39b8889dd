"""Progress of a long CLI step (renders): a rich progress bar when stderr is a terminal, one
plain log line per finished item otherwise (CI logs, pipes). CoACD's bar is `linkwork`'s."""

from __future__ import annotations

import sys
from collections.abc import Callable


class Reporter:
    """`with Reporter("render", total, say) as bar: ... bar.step("home.png")`; `say` None is
    quiet."""

    def __init__(self, label: str, total: int, say: Callable[[str], None] | None) -> None:
        self.label, self.total, self.say, self.count = label, total, say, 0
        self.bar = None
        if say is not None and total and sys.stderr.isatty():
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

            self.bar = Progress(
                label,
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self.task = self.bar.add_task(label, total=total)

    def __enter__(self) -> Reporter:
        if self.bar is not None:
            self.bar.start()
        return self

    def __exit__(self, *_exc) -> None:
        if self.bar is not None:
            self.bar.stop()

    def step(self, item: str) -> None:
        self.count += 1
        if self.bar is not None:
            self.bar.advance(self.task)
        elif self.say is not None:
            self.say(f"{self.label} {self.count}/{self.total}: {item}")
