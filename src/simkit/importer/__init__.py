"""`simkit import`: a URDF, xacro or MJCF to a spec plus the meshes it needs (issue 15).

The spec keeps the source's numbers exactly; gaps are filled with plausible values listed
under `estimated` and reported one line each (`--strict` refuses them), and every element
simkit does not keep is reported too. Output: DIR/NAME.yaml and DIR/meshes/*.stl (relative
paths), written only when the whole import succeeded.

Sub-packages by concern, each importing only those below it (an import-linter contract,
docs/architecture.md): `formats/` (one module per format behind one table: what a file is,
its reader, its kept source) and `write/` (the YAML written and validated once, the files
moved into place), then `fixups/` (spec edits, pose and mass steps that read the draft),
`translate/` (the read `Source` to the draft's spec, no format known), `draft.py` (the one
typed object every step receives), `read/` (what every reader shares) and `diagnostics.py`
(the one record and policy every step reports through).

The import picks the format once (formats.pick: the file's head read once), reads the file,
then passes one draft through `steps(format)` in order: translate.to_spec, the names made
legal, the closed loops made spec `loops` (translate/loops.py), the format's edits, the
refusals `--strict` asks for, the STEP budget, fixups.STEPS (rotors, base, home, stand,
limits), the loops' poses at the final home and the format's last steps; then the format keeps its
source (`keep`) and `write.finish` writes and validates the spec once and moves the files
into place whole (write/output.py). The staging folder is removed on every way out.
"""

from __future__ import annotations

import re
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer import fixups, formats, translate, write
from simkit.importer.diagnostics import Policy, Report
from simkit.importer.draft import DENSITY, Draft, Options, Unresolvable
from simkit.importer.fixups import names, step_budget
from simkit.importer.formats import Format
from simkit.importer.read.options import ReadOptions
from simkit.importer.translate import loops
from simkit.importer.write.output import staging


def _refused(draft: Draft) -> None:
    """Stop on the first problem `--strict` refuses (after the names and the format's
    edits, which may report more)."""
    draft.report.raise_refused()


def steps(fmt: Format) -> tuple[Callable[[Draft], None], ...]:
    """The import's steps for a file of format `fmt`, in order: each receives the draft
    and changes it."""
    return (
        translate.to_spec, names.legal, loops.close, *fmt.edits, _refused, step_budget.fit,
        *fixups.STEPS, loops.at_home, *fmt.after,
    )  # fmt: skip


@dataclass(frozen=True)
class Imported:
    """The written spec, its report lines and the number of meshes written."""

    spec_path: Path
    lines: tuple[str, ...]
    meshes: int
    links: int


def robot_name(path: Path, picked: formats.Picked | None = None) -> str:
    """A spec name (`[a-z][a-z0-9_]*`) from the name the file gives its robot (an MJCF's
    `model` attribute; `picked`, else the file's head is read), else the file name."""
    title = (picked or formats.pick(path)).title
    stem = (title or path.name.split(".")[0]).lower()
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
    picked = formats.pick(path)  # the file's head read once
    path = picked.path or path  # a model folder: the model file it names
    name = name or robot_name(path, picked)
    if not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        raise SpecError(str(path), None, "--name", f"'{name}' is not [a-z][a-z0-9_]*")
    options = Options(name, floating, hull_collision, density or DENSITY)
    report = Report(Policy(strict=strict))
    doc = formats.load(path, package_dirs, report, reading, picked)
    fmt = picked.format
    try:
        with staging(out_dir) as stage:  # removed on every way out, SIGTERM included
            draft = Draft(doc, path, stage, report, options, kept=doc.kept)
            try:
                for step in steps(fmt):
                    step(draft)
            except Unresolvable:
                write.refuse(draft)
            fmt.keep(draft)  # the kept source, `source` and `source_differences`
            spec_path = write.finish(draft, out_dir)
    finally:
        for folder in doc.scratch:  # what the reader wrote for the translation
            shutil.rmtree(folder, ignore_errors=True)
    return Imported(spec_path, tuple(report.lines), draft.meshes, len(draft.spec["links"]))
