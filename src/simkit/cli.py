"""The `simkit` command line. Thin: parse, call the library, turn errors into one line."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import TYPE_CHECKING

import click
from rich.console import Console

from simkit import __version__
from simkit.errors import SimkitError

if TYPE_CHECKING:
    from simkit.kitio.cache import Cache

err = Console(stderr=True, highlight=False, soft_wrap=True)
out = Console(highlight=False, soft_wrap=True)
RAY_HELP = "One Ray task per robot ($RAY_ADDRESS, else a local Ray); needs simkit[ray]."


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
    type=click.Path(file_okay=False),  # kept as typed: a URL here is refused (cache.py)
    default=None,
    help="Cache folder. [default: $SIMKIT_CACHE_DIR, else the user cache folder]",
)
@click.option("--no-cache", is_flag=True, help="Compute every step; read and write no cache.")
@click.option(
    "--cache-readonly",
    is_flag=True,
    envvar="SIMKIT_CACHE_READONLY",
    help="Read the caches, never write them (untrusted runners, e.g. fork pull requests).",
)
@click.option(
    "--remote-cache",
    default=None,
    envvar="SIMKIT_REMOTE_CACHE",
    help="Shared cache behind the local one, an fsspec URL such as s3://bucket/prefix.",
)
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
@click.option("--ray", "on_ray", is_flag=True, help=RAY_HELP)
def build(
    targets: tuple[str, ...],
    out_dir: Path,
    no_check: bool,
    quiet: bool,
    jobs: int | None,
    cache_dir: str | None,
    no_cache: bool,
    cache_readonly: bool,
    remote_cache: str | None,
    usd_format: str,
    no_step: bool,
    on_ray: bool,
) -> None:
    """Build kits for robot NAMEs (see `simkit list`) or spec files (PATH.yaml)."""
    if on_ray:
        options = {"check": not no_check, "usd_format": usd_format, "step": not no_step}
        # each worker opens its own cache from these (and its own $SIMKIT_CACHE_KEY)
        options["cache_args"] = {
            "root": cache_dir,
            "enabled": not no_cache,
            "readonly": cache_readonly or None,
            "remote": remote_cache,
        }
        _build_on_ray(targets, out_dir, quiet, options)
        return
    cache = None
    for target in targets:
        if not no_cache:  # a rebuild with nothing changed: one line, no heavy import
            from simkit.kitio import noop

            options = noop.options(usd_format, not no_step, not no_check)
            line = noop.unchanged(target, out_dir, cache_dir, options)
            if line:
                out.print(line, markup=False)
                continue
        if cache is None:
            cache = _open_cache(cache_dir, no_cache, cache_readonly, remote_cache)
        _build_one(target, out_dir, not no_check, quiet, jobs, cache, usd_format, not no_step)


def _build_one(
    target: str,
    out_dir: Path,
    check: bool,
    quiet: bool,
    jobs: int | None,
    cache: Cache,
    usd_format: str,
    step: bool,
) -> None:
    """The full build of one target (`simkit build`), and its summary line."""
    import os

    from simkit.kitio.cache import Stats
    from simkit.pipeline import build as run_build

    # a build renders nothing: MuJoCo then skips its OpenGL (glfw, cffi) imports
    os.environ.setdefault("MUJOCO_GL", "disable")
    cache.stats = Stats()  # each summary line counts its own robot's hits

    def progress(msg: str) -> None:
        if not quiet:
            err.print(f"[{target}] {msg}", markup=False)

    try:
        result = run_build(
            target,
            out_dir,
            check=check,
            progress=None if quiet else progress,
            cache=cache,
            jobs=jobs,
            usd_format=usd_format,
            step=step,
        )
    except SimkitError as exc:
        _fail(exc)
    for warning in result.warnings if not quiet else ():
        err.print(f"warning: {warning}", markup=False)
    hits = f"; cache local/remote/miss: {cache.stats.summary()}" if cache.enabled else ""
    out.print(_built_line(result) + hits, markup=False)


def _built_line(result) -> str:
    passed = sum(f.ok for f in result.findings)
    same = "" if result.changed else " (the same bytes as before: nothing rewritten)"
    return (
        f"{result.robot}: {len(result.files)} files in {result.kit_dir}, zip "
        f"{result.zip_path}{same}; {passed}/{len(result.findings)} checks passed"
    )


def _build_on_ray(targets: tuple[str, ...], out_dir: Path, quiet: bool, options: dict) -> None:
    """`simkit build --ray`: one Ray task per target, published here (simkit/cluster.py)."""
    from simkit.cluster import build_on_ray

    try:
        results = build_on_ray(targets, out_dir, None if quiet else _say, **options)
    except SimkitError as exc:
        _fail(exc)
        return
    for result in results:
        for warning in result.warnings if not quiet else ():
            err.print(f"warning: {warning}", markup=False)
        hits = f"; cache local/remote/miss: {result.cache_hits}" if result.cache_hits else ""
        out.print(_built_line(result) + hits, markup=False)


def _open_cache(dir_: str | None, off: bool, readonly: bool, remote: str | None) -> Cache:
    """The build's cache from the command line (a URL as --cache-dir: one-line error)."""
    from simkit.kitio.cache import Cache

    if off:
        return Cache.disabled()
    try:
        return Cache.at(dir_, readonly=readonly, remote=remote)
    except SimkitError as exc:
        _fail(exc)


@main.command()
@click.argument("kit_dir", type=click.Path(path_type=Path))
@click.option("-v", "--verbose", is_flag=True, help="Print every finding, not only failures.")
def check(kit_dir: Path, verbose: bool) -> None:
    """Run the checks on a built kit (folder or zip)."""
    import tempfile

    from simkit.check import run_checks
    from simkit.diff import load_kit, unpacked
    from simkit.errors import CheckFailed

    try:
        if kit_dir.is_dir():
            _published_together(kit_dir)
            findings = run_checks(kit_dir)
        elif kit_dir.is_file():  # a zip: read with kitread's caps, written as plain files
            files = load_kit(kit_dir)
            with tempfile.TemporaryDirectory(prefix="simkit-check-") as tmp:
                findings = run_checks(unpacked(kit_dir, files, Path(tmp)))
        else:
            raise SimkitError(f"{kit_dir}: no such kit folder or zip")
    except SimkitError as exc:
        _fail(exc)
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
    from simkit.diff_text import to_markdown, to_short_markdown

    try:
        report = diff_kits(old, new)
        if html_out is not None:
            from simkit.review.commands import diff_html

            diff_html(report, old, new, html_out, _say)
        if md_out is not None:
            full = (
                f"Full report with renders: `{html_out}`."
                if html_out is not None
                else "Full report: `simkit diff OLD NEW --html REPORT.html`."
            )
            _append(md_out, to_short_markdown(report, full))
    except SimkitError as exc:
        _fail(exc)
    click.echo(report.to_json() if as_json else to_markdown(report), nl=False)
    sys.exit(0 if report.equal else 1)


def _append(path: Path, text: str) -> None:
    """Append `text` to `path` (GitHub's job summary file is shared by the job's steps)."""
    try:
        with open(path, "a", encoding="utf-8") as handle:
            handle.write(text)
    except OSError as exc:
        raise SimkitError(f"{path}: cannot write ({exc.strerror or exc})") from None


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
@click.option("--cache-dir", type=click.Path(file_okay=False), default=None, help="As build's.")
@click.option("--cache-readonly", is_flag=True, envvar="SIMKIT_CACHE_READONLY", help="As build's.")
@click.option("--remote-cache", default=None, envvar="SIMKIT_REMOTE_CACHE", help="As build's.")
@click.option("--ray", "on_ray", is_flag=True, help=RAY_HELP)
def publish(
    robots: tuple[str, ...],
    out_dir: Path,
    quiet: bool,
    cache_dir: str | None,
    cache_readonly: bool,
    remote_cache: str | None,
    on_ray: bool,
) -> None:
    """Build ROBOTS (default: every robot in robots/) into zips, per-file folders and
    index.json, as the download site serves them under /assets/sim/."""
    from simkit.publish import publish as run_publish

    if on_ray:  # each worker opens its own cache from these (and its own $SIMKIT_CACHE_KEY)
        args = {"root": cache_dir, "readonly": cache_readonly or None, "remote": remote_cache}
        options = {"on_ray": True, "cache_args": args}
    else:
        options = {"cache": _open_cache(cache_dir, False, cache_readonly, remote_cache)}

    def progress(msg: str) -> None:
        if not quiet:
            err.print(msg, markup=False)

    try:
        index = run_publish(out_dir, robots or None, progress=progress, **options)
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
@click.option(
    "--xacro-arg", "xacro_args", multiple=True, help="NAME:=VALUE for $(arg NAME); repeatable."
)
@click.option(
    "--allow-env", "allow_env", multiple=True, help="Env var $(env)/$(optenv) may read; repeatable."
)
@click.option(
    "--allow-read",
    "allow_read",
    multiple=True,
    type=click.Path(file_okay=False, path_type=Path),
    help="Folder outside the robot's package that meshes and includes may read; repeatable.",
)
@click.option("--trust-xacro", is_flag=True, help="Run the xacro as is (trusted files only).")
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
    xacro_args: tuple[str, ...],
    allow_env: tuple[str, ...],
    allow_read: tuple[Path, ...],
    trust_xacro: bool,
) -> None:
    """Turn a URDF or xacro into OUT/NAME.yaml plus the meshes it needs."""
    from simkit.importer import import_robot
    from simkit.importer.reading import ReadOptions, parse_xacro_arg

    if floating_base and fixed_base:
        _fail(SimkitError("--floating-base and --fixed-base exclude each other"))
    floating = True if floating_base else False if fixed_base else None
    try:
        reading = ReadOptions(
            tuple(parse_xacro_arg(a) for a in xacro_args), allow_env, allow_read, trust_xacro
        )
        done = import_robot(
            path,
            out_dir,
            name=name,
            package_dirs=package_dirs,
            strict=strict,
            floating=floating,
            hull_collision=hull_collision,
            density=density,
            reading=reading,
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
