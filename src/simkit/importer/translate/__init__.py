"""Translate: the read source to the draft's spec (source -> draft), the import's first step.

`to_spec` decides the base from the robot's structure (base.py) unless the user or the
format set it, turns Y-up COLLADA meshes (up_axis.py) and converts links, joints and frames
(convert.py with links.py, joints.py, geometry.py, meshes.py, masses.py, solids.py,
ball_joints.py). It reads the one source model every format's reader gives
(`Source.robot`, read/model.py) and knows no format; the spec edits that follow (legal
names, the format's own edits, the STEP budget) are fix-ups (importer.steps).
"""

from __future__ import annotations

from dataclasses import replace

from simkit.importer.draft import Draft
from simkit.importer.translate import base, convert, loops, meshes
from simkit.importer.translate.up_axis import turn_y_up


def to_spec(draft: Draft) -> None:
    """The source to the draft's spec: the base decided, links, joints and frames;
    `draft.meshes` counts the meshes written to the staging folder."""
    source, report = draft.source, draft.report
    loops.second_parents(source, report)  # a link's later parent joints close loops
    if draft.options.floating is None and source.base is not None:  # the format says
        floating, why = source.base
        draft.options = replace(draft.options, floating=floating)
        report.assumed(source, source.robot.at, why)
    options = draft.options
    draft.legged, why = base.decide(source)
    floating = options.floating
    if floating is None:
        floating = draft.legged
        report.assumed(source, source.robot.at, why)
    mesh_writer = meshes.MeshWriter(draft.stage)
    mesh_writer.turn_y_up, why = turn_y_up(source)  # Y_UP COLLADA meshes drawn so: turned
    if why:
        report.changed(source, source.robot.at, why)
    draft.spec = convert.convert(
        source, options.name, mesh_writer, report, floating, options.hull_collision,
        options.density,
    )  # fmt: skip
    draft.changed()
    draft.meshes = len(mesh_writer.done)
