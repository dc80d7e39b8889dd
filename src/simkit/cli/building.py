"""`simkit build`, `simkit list` and `simkit publish`: the commands that make kits."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from simkit.cli.console import RAY_HELP, err, fail, out, say
from simkit.errors import SimkitError

if TYPE_CHECKING:
    from simkit.kitio.cache import Cache
    from simkit.pipeline import BuildResult


@click.command()
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
@click.option(
    "--accept-published",
    is_flag=True,
    help="First write the model's values into the spec's published: block where they "
    "disagree (only those values; comments and layout kept), and print each change.",
)
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
    accept_published: bool,
) -> None:
    """Build kits for robot NAMEs (see `simkit list`) or spec files (PATH.yaml)."""
    if accept_published:  # cli/accepting.py: rewrite the specs, then build them as usual
        from simkit.cli.accepting import accept_published as accept

        cache_ = _open_cache(cache_dir, no_cache, cache_readonly, remote_cache)
        for target in targets:
            if not quiet:
                err.print(f"[{target}] --accept-published: an unchecked build first", markup=False)
            try:
                lines = accept(target, usd_format, not no_step, cache_)
            except SimkitError as exc:
                fail(exc)
            for line in lines:
                out.print(line, markup=False)
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
        fail(exc)
    for warning in result.warnings if not quiet else ():
        err.print(f"warning: {warning}", markup=False)
    hits = f"; cache local/remote/miss: {cache.stats.summary()}" if cache.enabled else ""
    out.print(_built_line(result) + hits, markup=False)


def _built_line(result: BuildResult) -> str:
    """One built kit's summary (files, folder, zip, checks), local and Ray builds alike."""
    passed = sum(f.ok for f in result.findings)
    same = "" if result.changed else " (the same bytes as before: nothing rewritten)"
    return (
        f"{result.robot}: {len(result.files)} files in {result.kit_dir}, zip "
        f"{result.zip_path}{same}; {passed}/{len(result.findings)} checks passed"
    )


def _build_on_ray(
    targets: tuple[str, ...], out_dir: Path, quiet: bool, options: dict[str, Any]
) -> None:
    """`simkit build --ray`: one Ray task per target, published here (simkit/cluster.py)."""
    from simkit.cluster import build_on_ray

    try:
        results = build_on_ray(targets, out_dir, None if quiet else say, **options)
    except SimkitError as exc:
        fail(exc)
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
        fail(exc)


@click.command(name="list")
def list_robots() -> None:
    """List the robots simkit ships specs for."""
    from simkit.kitio.resources import robot_names

    for name in robot_names():
        out.print(name, markup=False)


@click.command()
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
@click.option(
    "--pictures/--no-pictures",
    default=True,
    show_default=True,
    help="Render each kit at its named poses for its page (MuJoCo, as simkit render).",
)
@click.option("--serve", is_flag=True, help="Then serve the site on 127.0.0.1 (Ctrl-C stops).")
@click.option("--port", type=click.IntRange(0, 65535), default=8000, show_default=True)
def publish(
    robots: tuple[str, ...],
    out_dir: Path,
    quiet: bool,
    cache_dir: str | None,
    cache_readonly: bool,
    remote_cache: str | None,
    on_ray: bool,
    pictures: bool,
    serve: bool,
    port: int,
) -> None:
    """Build ROBOTS (default: every robot in robots/) into zips, per-file folders, index.json
    and the pages (a gallery, one page per kit with the robot live), as the download site
    serves them under /assets/sim/."""
    from simkit.publish import publish as run_publish
    from simkit.review.view import pose_pictures, serve_site

    if on_ray:  # each worker opens its own cache from these (and its own $SIMKIT_CACHE_KEY)
        args = {"root": cache_dir, "readonly": cache_readonly or None, "remote": remote_cache}
        options = {"on_ray": True, "cache_args": args}
    else:
        options = {"cache": _open_cache(cache_dir, False, cache_readonly, remote_cache)}
    if pictures:
        options["pictures"] = pose_pictures

    def progress(msg: str) -> None:
        if not quiet:
            err.print(msg, markup=False)

    try:
        index = run_publish(out_dir, robots or None, progress=progress, **options)
    except SimkitError as exc:
        fail(exc)
    files = sum(len(kit["files"]) for kit in index["kits"])
    out.print(f"published {len(index['kits'])} kit(s), {files} files, to {out_dir}", markup=False)
    if serve:
        try:
            serve_site(out_dir, port, say)
        except SimkitError as exc:
            fail(exc)
