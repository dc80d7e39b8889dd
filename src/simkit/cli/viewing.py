"""`simkit render` and `simkit view`: pictures of a built kit (simkit/review)."""

from __future__ import annotations

from pathlib import Path

import click

from simkit.cli.console import fail, out, say
from simkit.errors import SimkitError


@click.command()
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
        paths = render_pngs(kit, out_dir, poses, size, camera, collision, None if quiet else say)
    except SimkitError as exc:
        fail(exc)
    out.print(f"{len(paths)} image(s) in {out_dir}", markup=False)


@click.command()
@click.argument("kit", type=click.Path(path_type=Path))
@click.option("--port", type=click.IntRange(0, 65535), default=8765, show_default=True)
@click.option("--no-browser", is_flag=True, help="Only serve; print the address.")
def view(kit: Path, port: int, no_browser: bool) -> None:
    """Show KIT (folder) in the browser: three.js on 127.0.0.1, joint sliders, named poses."""
    from simkit.review.view import serve_kit

    try:
        serve_kit(kit, port, open_browser=not no_browser, say=say)
    except SimkitError as exc:
        fail(exc)
