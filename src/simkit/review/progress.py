"""Progress of a long CLI step (renders): a rich progress bar when stderr is a terminal, one
plain log line per finished item otherwise (CI logs, pipes). CoACD's bar is `linkwork`'s."""

from __future__ import annotations

import sys
from collections.abc import Callable


class Reporter:
    """`with Reporter("render", say) as bar: bar.begin(total); ... bar.step("home.png")`;
    `say` None is quiet."""

    def __init__(self, label: str, say: Callable[[str], None] | None) -> None:
        self.label, self.say, self.total, self.count = label, say, 0, 0
        self.bar = None

    def begin(self, total: int) -> None:
        """Start the bar (on a terminal) once the number of items is known."""
        self.total = total
        if self.say is not None and total and sys.stderr.isatty():
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

            self.bar = Progress(
                self.label,
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self.task = self.bar.add_task(self.label, total=total)
            self.bar.start()

    def __enter__(self) -> Reporter:
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
