"""`simkit import`: a URDF (or xacro) to a spec plus the meshes it needs (issue 15).

The spec keeps the URDF's numbers exactly; gaps are filled with plausible values listed under
`estimated` and reported one line each (`--strict` refuses them), and every element simkit
does not keep is reported too. Output: DIR/NAME.yaml and DIR/meshes/*.stl (relative paths),
written only when the whole import succeeded.

The import is one in-memory draft (draft.py) passed through explicit, ordered steps:
`translate` (the URDF to a spec dict: convert.py, names.py, blocks.py), then the pose
fix-ups (fixups.STEPS: rotors, base, home, stand, limits), then `writer.finish`, which writes and
validates the spec once.
"""

from __future__ import annotations

import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer.draft import Draft
from simkit.importer.reading import ReadOptions
from simkit.importer.report import Report


@dataclass(frozen=True)
class Imported:
    """The written spec, its report lines and the number of meshes written."""

    spec_path: Path
    lines: tuple[str, ...]
    meshes: int
    links: int


def robot_name(path: Path) -> str:
    """A spec name (`[a-z][a-z0-9_]*`) from a file name."""
    stem = path.name.split(".")[0].lower()
    name = re.sub(r"[^a-z0-9_]+", "_", stem).strip("_") or "robot"
    return name if name[0].isalpha() else f"robot_{name}"


def translate(draft: Draft, name: str, floating: bool, hull_collision: bool, density: float) -> int:
    """The URDF to the draft's spec: links, joints, frames and kept blocks, names made legal,
    `--strict` problems refused, the STEP left out when the meshes are too large. Returns
    the number of meshes written to the staging folder."""
    from simkit.importer import blocks, convert, meshes, names
    from simkit.importer.step_budget import step_fits
    from simkit.importer.up_axis import turn_y_up

    source, report = draft.source, draft.report
    mesh_writer = meshes.MeshWriter(draft.stage)
    mesh_writer.turn_y_up, why = turn_y_up(source)  # Y_UP COLLADA meshes drawn so: turned
    if why:
        report.changed(source, source.root, why)
    spec = convert.convert(source, name, mesh_writer, report, floating, hull_collision, density)
    renames = names.make_legal(spec, source, report)
    blocks.keep(spec, source, report, blocks.collect(source), renames)
    if report.strict and report.problems:
        first = report.problems[0]
        first.more = len(report.problems) - 1
        raise SpecError(first.file, first.line, first.field, first.message, first.more)
    fits, why = step_fits(spec, draft.stage)
    if not fits:
        spec["step"] = False
        report.changed(source, source.root, why)
    draft.spec = spec
    draft.changed()
    return len(mesh_writer.done)


def import_robot(
    path: Path,
    out_dir: Path,
    name: str | None = None,
    package_dirs: tuple[Path, ...] = (),
    strict: bool = False,
    floating: bool | None = None,
    hull_collision: bool = False,
    reading: ReadOptions | None = None,
    density: float | None = None,
) -> Imported:
    """Import `path` into `out_dir`; SpecError (one line) on input simkit cannot use.
    `floating`: True or False sets the base; None decides it from the robot's structure
    (base.py; reported). `hull_collision`: links whose URDF collision has meshes collide
    with their visual solid's convex hull instead (one piece; reported per link).
    `reading`: what the reader may do (xacro args, environment, files outside the package;
    importer/reading.py). `density` (kg/m^3, default masses.DENSITY): a massless link's
    mass from its solid."""
    from simkit.importer import base, fixups, masses, source, writer

    name = name or robot_name(path)
    if not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        raise SpecError(str(path), None, "--name", f"'{name}' is not [a-z][a-z0-9_]*")
    report = Report(strict=strict)
    doc = source.load(path, package_dirs, report, reading)
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=out_dir, prefix=".import-") as tmp:
        draft = Draft(doc, path, Path(tmp), report)
        draft.legged, why = base.decide(doc)
        if floating is None:
            floating = draft.legged
            draft.report.assumed(doc, doc.root, why)
        meshes = translate(draft, name, floating, hull_collision, density or masses.DENSITY)
        for step in fixups.STEPS:
            step(draft)
        spec_path = writer.finish(draft, out_dir)
    return Imported(spec_path, tuple(draft.report.lines), meshes, len(draft.spec["links"]))
