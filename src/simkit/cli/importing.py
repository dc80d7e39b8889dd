"""`simkit import`: a URDF, xacro, MJCF, SDFormat file or USD to a spec YAML and meshes."""

from __future__ import annotations

from pathlib import Path

import click

from simkit.cli.console import fail, out
from simkit.errors import SimkitError


@click.command(name="import")
@click.argument("path", type=click.Path(path_type=Path))
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
    help="kg/m^3 of a massless link's visual solid, for its estimated mass. [default: 1400, "
    "the corpora's median link (docs/import-corpus.md)]",
)
@click.option(
    "--hull",
    "hull_collision",
    is_flag=True,
    help="Collision meshes: the visual's convex hull (one piece) instead of the source's.",
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
@click.option(
    "--variant", default=None, help="USD: the Physics variant to read. [default: the stage's]"
)
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
    variant: str | None,
) -> None:
    """Turn a URDF, a xacro, an MJCF (MuJoCo's XML, a <mujoco> file), an SDFormat file
    (.sdf, or a Gazebo model folder with model.config) or a USD (a UsdPhysics articulation:
    .usd, .usda, .usdc) at PATH into OUT/NAME.yaml plus the meshes it needs."""
    from simkit.importer import import_robot
    from simkit.importer.read.options import ReadOptions, parse_xacro_arg

    if floating_base and fixed_base:
        fail(SimkitError("--floating-base and --fixed-base exclude each other"))
    floating = True if floating_base else False if fixed_base else None
    try:
        reading = ReadOptions(
            tuple(parse_xacro_arg(a) for a in xacro_args),
            allow_env,
            allow_read,
            trust_xacro,
            variant,
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
        fail(exc)
    if not quiet:
        for line in done.lines:
            out.print(line, markup=False)
    out.print(
        f"{done.spec_path}: {done.links} links, {done.meshes} meshes, "
        f"{len(done.lines)} report lines",
        markup=False,
    )
