"""`simkit check` and `simkit diff`: the commands that read built kits and report."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from simkit.cli.console import fail, out, say
from simkit.errors import SimkitError


@click.command()
@click.argument("kit_dir", type=click.Path(path_type=Path))
@click.option("-v", "--verbose", is_flag=True, help="Print every finding, not only failures.")
@click.option(
    "--source",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Also compare the kit with the file it was imported from: a URDF, a xacro, an "
    "MJCF, an SDFormat file or a USD (kinematics, limits, mass).",
)
def check(kit_dir: Path, verbose: bool, source: Path | None) -> None:
    """Run the checks on a built kit (folder or zip); with --source, also compare it with
    the URDF, xacro, MJCF, SDFormat file or USD it was imported from."""
    import tempfile

    from simkit.check import run_checks
    from simkit.diff import load_kit, unpacked
    from simkit.errors import CheckFailed

    try:
        if source is not None and not source.is_file():
            raise SimkitError(f"{source}: no such source file")
        if kit_dir.is_dir():
            _published_together(kit_dir)
            findings = run_checks(kit_dir, source=source)
        elif kit_dir.is_file():  # a zip: read with kitread's caps, written as plain files
            files = load_kit(kit_dir)
            with tempfile.TemporaryDirectory(prefix="simkit-check-") as tmp:
                findings = run_checks(unpacked(kit_dir, files, Path(tmp)), source=source)
        else:
            raise SimkitError(f"{kit_dir}: no such kit folder or zip")
    except SimkitError as exc:
        fail(exc)
    failed = [f for f in findings if not f.ok]
    for finding in findings:
        if verbose or not finding.ok:
            out.print(finding.line(), markup=False)
    out.print(f"{len(findings) - len(failed)} passed, {len(failed)} failed", markup=False)
    if failed:
        sys.exit(CheckFailed.exit_code)


def _published_together(kit_dir: Path) -> None:
    """A kit in a build folder: its zip and the manifest beside them agree (kitio/atomic.py),
    else one line. Reads only."""
    from simkit.errors import CheckFailed
    from simkit.kitio.manifest import mismatch

    line = mismatch(kit_dir)
    if line:
        raise CheckFailed(line)


@click.command()
@click.argument("old", type=click.Path(path_type=Path))
@click.argument("new", type=click.Path(path_type=Path))
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
@click.option(
    "--html",
    "html_out",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Also write a self-contained HTML report with renders of every named pose.",
)
@click.option(
    "--markdown",
    "md_out",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    help="Also write a short Markdown summary (GitHub job summary, PR comment); appends.",
)
def diff(old: Path, new: Path, as_json: bool, html_out: Path | None, md_out: Path | None) -> None:
    """Report what changed between two kits (folders or zips) beyond the checks' tolerances;
    exit 0 equal, 1 different."""
    from simkit.diff import diff_kits
    from simkit.diff.markdown import to_markdown, to_short_markdown

    try:
        report = diff_kits(old, new)
        if html_out is not None:
            from simkit.review.commands import diff_html

            diff_html(report, old, new, html_out, say)
        if md_out is not None:
            full = (
                f"Full report with renders: `{html_out}`."
                if html_out is not None
                else "Full report: `simkit diff OLD NEW --html REPORT.html`."
            )
            _append(md_out, to_short_markdown(report, full))
    except SimkitError as exc:
        fail(exc)
    click.echo(report.to_json() if as_json else to_markdown(report), nl=False)
    sys.exit(0 if report.equal else 1)


def _append(path: Path, text: str) -> None:
    """Append `text` to `path` (GitHub's job summary file is shared by the job's steps)."""
    try:
        with open(path, "a", encoding="utf-8") as handle:
            handle.write(text)
    except OSError as exc:
        raise SimkitError(f"{path}: cannot write ({exc.strerror or exc})") from None
