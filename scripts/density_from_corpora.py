"""Measure the mass per visual volume of real robot links (issue 32, class 6a).

    python scripts/density_from_corpora.py FOLDER [FOLDER ...] [--exclude GLOB ...]
        [--movable-only]

Every URDF under the folders (sorted) is read with yourdfpy, without loading meshes through
it (`--movable-only`: only URDFs with a movable joint, robots rather than props); each
link that gives an `<inertial>` mass > 0 and has visual geometry whose every piece
is a closed solid (primitives, or a mesh trimesh finds watertight) gives one ratio: its mass
over the summed volume of its visual pieces (kg/m^3, scale applied), each distinct (mass,
volume) pair once (a link shared by several variants of one robot counts once). A mesh that is not
closed has no volume and its link is skipped; so is a link whose mesh file is missing. The
median over all links is the importer's default density for a link with a visual solid and
no mass: most links are hollow shells, so full metal density (2700 kg/m^3) overestimates
them. Prints the count, quartiles and median. No robot is named here.
"""

from __future__ import annotations

import argparse
import fnmatch
import math
import statistics
import sys
from pathlib import Path


def _volume(geometry, base: Path) -> float | None:
    """m^3 of one visual geometry, or None when it holds no closed solid."""
    import trimesh

    if geometry.box is not None:
        return float(math.prod(geometry.box.size))
    if geometry.cylinder is not None:
        return math.pi * geometry.cylinder.radius**2 * geometry.cylinder.length
    if geometry.sphere is not None:
        return 4.0 / 3.0 * math.pi * geometry.sphere.radius**3
    mesh = geometry.mesh
    if mesh is None:
        return None
    name = mesh.filename.split("://", 1)[-1]
    candidates = [base / name] + [p / name for p in base.parents]
    path = next((p for p in candidates if p.is_file()), None)
    if path is None:
        return None
    try:
        loaded = trimesh.load_mesh(path, force="mesh")
    except Exception:  # trimesh raises many kinds on a file it cannot read
        return None
    if not loaded.is_watertight or loaded.volume <= 0:
        return None
    scale = mesh.scale if mesh.scale is not None else (1.0, 1.0, 1.0)
    scale = [scale] * 3 if isinstance(scale, (int, float)) else list(scale)
    return float(loaded.volume) * abs(math.prod(float(s) for s in scale))


MOVABLE = {"revolute", "continuous", "prismatic"}


def ratios(urdf: Path, movable_only: bool = False) -> list[tuple[float, float]]:
    """(mass kg, visual volume m^3) of each link of one URDF that gives both, at 6 digits."""
    import yourdfpy

    try:
        robot = yourdfpy.URDF.load(str(urdf), load_meshes=False, build_scene_graph=False)
    except Exception:  # an unreadable URDF gives nothing
        return []
    out: list[tuple[float, float]] = []
    if movable_only and not any(j.type in MOVABLE for j in robot.robot.joints):
        return out
    for link in robot.robot.links:
        mass = link.inertial.mass if link.inertial is not None else None
        if not mass or mass <= 0 or not link.visuals:
            continue
        volumes = [_volume(v.geometry, urdf.parent) for v in link.visuals]
        if any(v is None or v <= 0 for v in volumes):
            continue
        out.append((float(f"{float(mass):.6g}"), float(f"{sum(volumes):.6g}")))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--exclude", action="append", default=[], help="glob of paths to skip")
    parser.add_argument("--movable-only", action="store_true", help="robots: a movable joint")
    args = parser.parse_args(argv)
    links: set[tuple[float, float]] = set()
    files = sorted(
        p
        for folder in args.folders
        for p in folder.rglob("*.urdf")
        if not any(fnmatch.fnmatch(str(p.relative_to(folder)), g) for g in args.exclude)
    )
    for urdf in files:
        links.update(ratios(urdf, args.movable_only))
    found = sorted(mass / volume for mass, volume in links)
    if not found:
        print("no link gives both a mass and a closed visual solid", file=sys.stderr)
        return 1
    q1, median, q3 = statistics.quantiles(found, n=4)
    print(
        f"{len(found)} distinct links of {len(files)} URDFs: mass / visual volume median "
        f"{median:.0f} kg/m^3 (quartiles {q1:.0f}, {q3:.0f})"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
