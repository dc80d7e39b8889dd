"""`simkit import`: a URDF (or xacro) to a spec plus the meshes it needs (issue 15).

The spec keeps the URDF's numbers exactly; gaps are filled with plausible values listed under
`estimated` and reported one line each (`--strict` refuses them), and every element simkit
does not keep is reported too. Output: DIR/NAME.yaml and DIR/meshes/*.stl (relative paths),
written only when the whole import succeeded.

Sub-packages by concern, each importing only those before it (an import-linter contract,
docs/architecture.md): `read/` (one reader per format behind one table, to a `Source`),
`translate/` (the source to the draft's spec), `fixups/` (pose and mass steps that read only
the draft), `write/` (provenance, the YAML written and validated once, the files moved into
place). Below them sit `draft.py` (the one typed object every step receives) and
`diagnostics.py` (the one record and policy every step reports through).

The import reads the file, then passes one draft through `STEPS` in order (translate.to_spec,
then fixups.STEPS: rotors, base, home, stand, limits), then `write.finish`, which keeps the
source (write/provenance.py), writes and validates the spec once, and moves the files into
place whole (write/output.py). The staging folder is removed on every way out.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer import fixups, read, translate, write
from simkit.importer.diagnostics import Policy, Report
from simkit.importer.draft import DENSITY, Draft, Options, Unresolvable
from simkit.importer.read import mjcf
from simkit.importer.read.options import ReadOptions
from simkit.importer.write import provenance
from simkit.importer.write.output import staging

#: the import's steps, in order: each receives the draft and changes it
STEPS = (translate.to_spec, *fixups.STEPS)


@dataclass(frozen=True)
class Imported:
    """The written spec, its report lines and the number of meshes written."""

    spec_path: Path
    lines: tuple[str, ...]
    meshes: int
    links: int


def robot_name(path: Path) -> str:
    """A spec name (`[a-z][a-z0-9_]*`) from an MJCF's `model` attribute, else the file name."""
    model = mjcf.model_name(path) if mjcf.is_mjcf(path) else None
    stem = (model or path.name.split(".")[0]).lower()
    name = re.sub(r"[^a-z0-9_]+", "_", stem).strip("_") or "robot"
    return name if name[0].isalpha() else f"robot_{name}"


def import_robot(
    path: Path,
    out_dir: Path,
    name: str | None = None,
    package_dirs: tuple[Path, ...] = (),
    strict: bool = False,
    floating: bool | None = None,
    hull_collision: bool = False,
    density: float | None = None,
    reading: ReadOptions | None = None,
) -> Imported:
    """Import `path` into `out_dir`; SpecError (one line) on input simkit cannot use.
    `floating`: True or False sets the base; None decides it from the robot's structure
    (translate/base.py; reported). `hull_collision`: links whose URDF collision has meshes collide
    with their visual solid's convex hull instead (one piece; reported per link).
    `density` (kg/m^3, default draft.DENSITY): a massless link's mass from its solid.
    `reading`: what the reader may do (xacro args, environment, files outside the package;
    importer/read/options.py)."""
    name = name or robot_name(path)
    if not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        raise SpecError(str(path), None, "--name", f"'{name}' is not [a-z][a-z0-9_]*")
    options = Options(name, floating, hull_collision, density or DENSITY)
    report = Report(Policy(strict=strict))
    doc = read.load(path, package_dirs, report, reading)
    kept = provenance.as_read(doc)  # before any rewrite (spherical joints)
    with staging(out_dir) as stage:  # removed on every way out, SIGTERM included
        draft = Draft(doc, path, stage, report, options, kept=kept)
        try:
            for step in STEPS:
                step(draft)
        except Unresolvable:
            write.refuse(draft)
        spec_path = write.finish(draft, out_dir)
    return Imported(spec_path, tuple(report.lines), draft.meshes, len(draft.spec["links"]))
