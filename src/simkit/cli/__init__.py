"""The `simkit` command line. Thin: parse, call the library, turn errors into one line.

This package holds the group and its error handling; each command lives in a module by
what it does (building, checking, importing, viewing), registered on `main` below."""

from __future__ import annotations

import sys
from typing import Any

import click

from simkit import __version__
from simkit.cli.building import build, list_robots, publish
from simkit.cli.checking import check, diff
from simkit.cli.console import err, fail
from simkit.cli.importing import import_urdf
from simkit.cli.viewing import render, view
from simkit.errors import SimkitError


class _Main(click.Group):
    """The `simkit` group: SIGTERM, SIGINT and SIGHUP run the normal clean-up (staging
    folders removed, locks released, workers stopped), then one line and 128 + signal. An
    I/O error no command turned into a `SimkitError` (an unwritable path, a full disk) is one
    line naming the path, after the same clean-up."""

    def main(self, *args: Any, **kwargs: Any) -> Any:
        from simkit.kitio import interrupt

        try:
            with interrupt.installed():
                return super().main(*args, **kwargs)
        except interrupt.Interrupted as exc:
            interrupt.ignore()  # the clean-up is done: no late signal may end the exit
            err.print(f"simkit: {exc.line()}", markup=False)
            sys.exit(exc.code)
        except OSError as exc:  # click itself handles a closed pipe (EPIPE)
            where = f"{exc.filename}: " if exc.filename is not None else ""
            fail(SimkitError(f"{where}{exc.strerror or exc}"))

    def invoke(self, ctx: click.Context) -> Any:
        """A Ctrl-C no command handled is `Interrupted` (130), not click's `Aborted!`."""
        import signal

        from simkit.kitio import interrupt

        try:
            return super().invoke(ctx)
        except KeyboardInterrupt:
            raise interrupt.Interrupted(signal.SIGINT) from None


@click.group(cls=_Main, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="simkit")
def main() -> None:
    """Turn robot specs into complete, checked simulation kits."""


for _command in (build, check, list_robots, diff, render, view, publish, import_urdf):
    main.add_command(_command)
