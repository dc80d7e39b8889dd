"""Translate: the read source to the draft's spec (format -> draft), the import's first step.

`to_spec` drops identical duplicate links and joints and declares an undeclared mounting
frame (declare.py), decides the base from the robot's structure (base.py) unless the user set
it, turns Y-up COLLADA meshes (up_axis.py), converts links, joints and frames (convert.py with
links.py, joints.py, geometry.py, meshes.py, masses.py, solids.py, ball_joints.py), makes
names legal (names.py), keeps the URDF blocks (blocks.py), refuses what `--strict` refuses,
and leaves the STEP out when the meshes are too large (step_budget.py).
"""

from __future__ import annotations

from simkit.importer.draft import Draft
from simkit.importer.translate import base, blocks, convert, declare, meshes, names
from simkit.importer.translate.step_budget import step_fits
from simkit.importer.translate.up_axis import turn_y_up


def to_spec(draft: Draft) -> None:
    """The URDF to the draft's spec: the base decided, links, joints, frames and kept
    blocks, names made legal, `--strict` problems refused, the STEP left out when the meshes
    are too large; `draft.meshes` counts the meshes written to the staging folder."""
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
