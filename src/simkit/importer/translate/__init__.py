"""Translate: the read source to the draft's spec (format -> draft), the import's first step.

`to_spec` drops identical duplicate links and joints and declares an undeclared mounting
frame (declare.py), decides the base from the robot's structure (base.py) unless the user set
it, turns Y-up COLLADA meshes (up_axis.py), converts links, joints and frames (convert.py with
links.py, joints.py, geometry.py, meshes.py, masses.py, solids.py, ball_joints.py), makes
names legal (names.py), keeps the URDF blocks (blocks.py), refuses what `--strict` refuses,
and leaves the STEP out when the meshes are too large (step_budget.py).
"""

from __future__ import annotations

import copy
import shutil
import tempfile
from dataclasses import replace
from pathlib import Path

from simkit.importer.draft import Draft
from simkit.importer.read.mjcf import MjcfSource
from simkit.importer.translate import base, blocks, convert, declare, meshes, mjcf, names
from simkit.importer.translate.step_budget import step_fits
from simkit.importer.translate.up_axis import turn_y_up


def to_spec(draft: Draft) -> None:
    """The URDF to the draft's spec: the base decided, links, joints, frames and kept
    blocks, names made legal, `--strict` problems refused, the STEP left out when the meshes
    are too large; `draft.meshes` counts the meshes written to the staging folder. An MJCF
    is first made the URDF-shaped tree this translation takes (mjcf.py)."""
    if isinstance(draft.source, MjcfSource) and draft.source.root is None:
        scratch = Path(tempfile.mkdtemp(prefix="simkit-mjcf-"))
        try:
            _from_mjcf(draft, scratch)
            _translate(draft)
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
        return
    _translate(draft)


def _from_mjcf(draft: Draft, scratch: Path) -> None:
    """The MJCF's tree, its meshes in `scratch` (readable by the mesh reader), the base
    floating where the MJCF's root has a free joint (unless the user set it), the tree as
    read kept for the source differences."""
    source = draft.source
    source.root, floating, source.listed = mjcf.to_tree(source, scratch)
    source.packages.allow_read = (*source.packages.allow_read, scratch.resolve())
    if draft.options.floating is None:
        draft.options = replace(draft.options, floating=floating)
        why = (
            "floating base: the MJCF's root body has a free joint; --fixed-base bolts it"
            if floating
            else "fixed base: the MJCF's root body has no free joint; --floating-base frees it"
        )
        draft.report.assumed(source, source.root, why)
    draft.kept = replace(source, root=copy.deepcopy(source.root))


def _translate(draft: Draft) -> None:
    source, report, options = draft.source, draft.report, draft.options
    declare.identical_duplicates(source, report)  # an include expanded twice
    declare.mounting_frame(source, report)  # an undeclared parent above the root
    draft.legged, why = base.decide(source)
    floating = options.floating
    if floating is None:
        floating = draft.legged
        report.assumed(source, source.root, why)
    mesh_writer = meshes.MeshWriter(draft.stage)
    mesh_writer.turn_y_up, why = turn_y_up(source)  # Y_UP COLLADA meshes drawn so: turned
    if why:
        report.changed(source, source.root, why)
    spec = convert.convert(
        source, options.name, mesh_writer, report, floating, options.hull_collision,
        options.density,
    )  # fmt: skip
    renames = names.make_legal(spec, source, report)
    draft.renames = renames
    blocks.keep(spec, source, report, blocks.collect(source), renames)
    report.raise_refused()
    fits, why = step_fits(spec, draft.stage)
    if not fits:
        spec["step"] = False
        report.changed(source, source.root, why)
    draft.spec = spec
    draft.changed()
    draft.meshes = len(mesh_writer.done)
