"""The `simkit` command line. Thin: parse, call the library, turn errors into one line."""

from __future__ import annotations

import sys
from pathlib import Path

import click
from rich.console import Console

from simkit import __version__
from simkit.errors import SimkitError

err = Console(stderr=True, highlight=False, soft_wrap=True)
out = Console(highlight=False, soft_wrap=True)


def _fail(exc: SimkitError) -> None:
    err.print(f"simkit: error: {exc}", markup=False)
    sys.exit(exc.exit_code)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="simkit")
def main() -> None:
    """Turn robot specs into complete, checked simulation kits."""


@main.command()
@click.argument("targets", nargs=-1, required=True)
@click.option(
    "--out",
    "out_dir",
    type=click.Path(path_type=Path),  # a file here is refused in one line (atomic.py)
    default=Path("build"),
    show_default=True,
    help="Folder for kits and zips.",
)
@click.option("--no-check", is_flag=True, help="Skip the check stage (not recommended).")
@click.option("-q", "--quiet", is_flag=True, help="Print only errors and the result.")
@click.option(
    "-j",
    "--jobs",
    type=click.IntRange(min=1),
    default=None,
    help="Worker processes for slow per-link steps (CoACD). [default: all cores]",
)
@click.option(
    "--cache-dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=None,
    help="Cache folder. [default: $SIMKIT_CACHE_DIR, else the user cache folder]",
)
@click.option("--no-cache", is_flag=True, help="Compute every step; read and write no cache.")
@click.option(
    "--usd-format",
    type=click.Choice(["usda", "usdc"]),
    default="usda",
    show_default=True,
    help="USD as text (diffable) or binary crate.",
)
@click.option(
    "--no-step",
    is_flag=True,
    help="Leave out step/NAME.step (the STEP assembly; saves the Open CASCADE time).",
)
def build(
    targets: tuple[str, ...],
    out_dir: Path,
    no_check: bool,
    quiet: bool,
    jobs: int | None,
    cache_dir: Path | None,
    no_cache: bool,
    usd_format: str,
    no_step: bool,
) -> None:
    """Build kits for robot NAMEs (see `simkit list`) or spec files (PATH.yaml)."""
    from simkit.kitio.cache import Cache
    from simkit.pipeline import build as run_build

    cache = Cache.disabled() if no_cache else Cache.at(cache_dir)

    for target in targets:

        def progress(msg: str, _t: str = target) -> None:
            if not quiet:
                err.print(f"[{_t}] {msg}", markup=False)

        try:
            result = run_build(
                target,
                out_dir,
                check=not no_check,
                progress=None if quiet else progress,
                cache=cache,
                jobs=jobs,
                usd_format=usd_format,
                step=not no_step,
            )
        except SimkitError as exc:
            _fail(exc)
        passed = sum(f.ok for f in result.findings)
        out.print(
            f"{result.robot}: {len(result.files)} files in {result.kit_dir}, zip "
            f"{result.zip_path}; {passed}/{len(result.findings)} checks passed",
            markup=False,
        )


@main.command()
@click.argument("kit_dir", type=click.Path(path_type=Path))
@click.option("-v", "--verbose", is_flag=True, help="Print every finding, not only failures.")
def check(kit_dir: Path, verbose: bool) -> None:
    """Run the checks on a built kit folder."""
    from simkit.check import run_checks
    from simkit.errors import CheckFailed

    try:
        if not kit_dir.is_dir():
            raise SimkitError(f"{kit_dir}: no such kit folder")
        findings = run_checks(kit_dir)
    except SimkitError as exc:
        _fail(exc)
    failed = [f for f in findings if not f.ok]
    for finding in findings:
        if verbose or not finding.ok:
            out.print(finding.line(), markup=False)
    out.print(f"{len(findings) - len(failed)} passed, {len(failed)} failed", markup=False)
    if failed:
        sys.exit(CheckFailed.exit_code)


@main.command(name="list")
def list_robots() -> None:
    """List the robots simkit ships specs for."""
    from simkit.kitio.resources import robot_names

    for name in robot_names():
        out.print(name, markup=False)


@main.command()
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
def diff(old: Path, new: Path, as_json: bool, html_out: Path | None) -> None:
    """Report what changed between two kits (folders or zips); exit 0 equal, 1 different."""
    from simkit.diff import diff_kits, to_markdown

    try:
        report = diff_kits(old, new)
        if html_out is not None:
            from simkit.review.commands import diff_html

            diff_html(report, old, new, html_out, _say)
    except SimkitError as exc:
        _fail(exc)
    click.echo(report.to_json() if as_json else to_markdown(report), nl=False)
    sys.exit(0 if report.equal else 1)


def _say(msg: str) -> None:
    err.print(msg, markup=False)


@main.command()
@click.argument("kit", type=click.Path(path_type=Path))
@click.option("--out", "out_dir", type=click.Path(file_okay=False, path_type=Path), required=True)
@click.option("--pose", "poses", multiple=True, help="A named pose (repeat). [default: all]")
@click.option("--size", default="640x480", show_default=True, help="WIDTHxHEIGHT in pixels.")
@click.option(
    "--camera",
    default=None,
    help="AZIMUTH,ELEVATION[,DISTANCE[,X,Y,Z]] (deg, deg, m). [default: 135,-20, fitted]",
)
@click.option("--collision", is_flag=True, help="Show collision geometry, translucent.")
@click.option("-q", "--quiet", is_flag=True, help="Print only errors and the result.")
def render(
    kit: Path,
    out_dir: Path,
    poses: tuple[str, ...],
    size: str,
    camera: str | None,
    collision: bool,
    quiet: bool,
) -> None:
    """Render KIT (folder or zip) to OUT/POSE.png with MuJoCo, one image per named pose."""
    from simkit.review.commands import render_pngs

    try:
        paths = render_pngs(kit, out_dir, poses, size, camera, collision, None if quiet else _say)
    except SimkitError as exc:
        _fail(exc)
    out.print(f"{len(paths)} image(s) in {out_dir}", markup=False)


@main.command()
@click.argument("kit", type=click.Path(path_type=Path))
@click.option("--port", type=click.IntRange(0, 65535), default=8765, show_default=True)
@click.option("--no-browser", is_flag=True, help="Only serve; print the address.")
def view(kit: Path, port: int, no_browser: bool) -> None:
    """Show KIT (folder) in the browser: three.js on 127.0.0.1, joint sliders, named poses."""
    from simkit.review.view import serve_kit

    try:
        serve_kit(kit, port, open_browser=not no_browser, say=_say)
    except SimkitError as exc:
        _fail(exc)


@main.command()
@click.argument("robots", nargs=-1)
@click.option(
    "--out",
    "out_dir",
    type=click.Path(file_okay=False, path_type=Path),
    default=Path("build/assets/sim"),
    show_default=True,
    help="The site's /assets/sim/ folder (replaced as a whole).",
)
@click.option("-q", "--quiet", is_flag=True, help="Print only errors and the result.")
def publish(robots: tuple[str, ...], out_dir: Path, quiet: bool) -> None:
    """Build ROBOTS (default: every robot in robots/) into zips, per-file folders and
    index.json, as the download site serves them under /assets/sim/."""
    from simkit.publish import publish as run_publish

    def progress(msg: str) -> None:
        if not quiet:
            err.print(msg, markup=False)

    try:
        index = run_publish(out_dir, robots or None, progress=progress)
    except SimkitError as exc:
        _fail(exc)
    files = sum(len(kit["files"]) for kit in index["kits"])
    out.print(f"published {len(index['kits'])} kit(s), {files} files, to {out_dir}", markup=False)


@main.command(name="import")
@click.argument("path", type=click.Path(dir_okay=False, path_type=Path))
@click.option("--name", default=None, help="Spec name [a-z][a-z0-9_]*. [default: from PATH]")
@click.option(
    "--package-dir",
    "package_dirs",
    multiple=True,
    type=click.Path(file_okay=False, path_type=Path),
    help="Folder holding ROS packages (or a package) for package:// URIs; repeatable.",
)
@click.option("--strict", is_flag=True, help="Refuse instead of estimating missing values.")
@click.option("--floating-base", is_flag=True, help="The root link moves freely (legged).")
@click.option(
    "--fixed-base",
    is_flag=True,
    help="The root link is bolted to the world. [default: decided from the robot's limbs]",
)
@click.option(
    "--density",
    type=click.FloatRange(min=1.0, max=25000.0),
    default=None,
    help="kg/m^3 of a massless link's visual solid, for its estimated mass. [default: 2700]",
)
@click.option(
    "--hull",
    "hull_collision",
    is_flag=True,
    help="Collision meshes: the visual's convex hull (one piece) instead of the URDF's.",
)
@click.option("--out", "out_dir", required=True, type=click.Path(file_okay=False, path_type=Path))
@click.option("-q", "--quiet", is_flag=True, help="Print only errors and the result.")
def import_urdf(
    path: Path,
    name: str | None,
    package_dirs: tuple[Path, ...],
    strict: bool,
    floating_base: bool,
    fixed_base: bool,
    density: float | None,
    hull_collision: bool,
    out_dir: Path,
    quiet: bool,
) -> None:
    """Turn a URDF or xacro into OUT/NAME.yaml plus the meshes it needs."""
    from simkit.importer import import_robot

    if floating_base and fixed_base:
        raise click.UsageError("--floating-base and --fixed-base exclude each other")
    floating = True if floating_base else False if fixed_base else None
    try:
        done = import_robot(
            path,
            out_dir,
            name=name,
            package_dirs=package_dirs,
            strict=strict,
            floating=floating,
            hull_collision=hull_collision,
            density=density,
        )
    except SimkitError as exc:
        _fail(exc)
        return
    if not quiet:
        for line in done.lines:
            out.print(line, markup=False)
    out.print(
        f"{done.spec_path}: {done.links} links, {done.meshes} meshes, "
        f"{len(done.lines)} report lines",
        markup=False,
    )


if __name__ == "__main__":  # pragma: no cover
    main()
