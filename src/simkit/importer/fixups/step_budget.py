"""Whether an imported robot's kit gets a STEP assembly: its visual CAD meshes must fit.

A link from a mesh file becomes a faceted solid in the STEP: one planar face, its loop,
edges, plane and points per triangle, about 2.3 kB of STEP text per triangle (measured with
Open CASCADE 7.8 on a quadruped's knee: 3,478 triangles, 8.2 MB). A robot with 337,000 visual
triangles would get a 790 MB STEP that takes minutes to write and re-check, over the kit's
64 MiB per-file cap. Above `MAX_TRIANGLES` the importer writes `step: false` in the spec and
says so on one line; the user can set it back to true.

A link whose solid holds a mesh is faceted whole: its primitives too, tessellated as
derive/solids.py makes them (a sphere at 96 segments is 4,608 triangles, 11 MB of STEP), so
they are counted (`FACETED`; issue 32: humanoids whose mesh links carry spheres went over the
cap with their meshes alone under the budget). A link of primitives only is exact in the STEP.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simkit.importer.draft import Draft

#: Visual mesh triangles a kit's STEP can hold: about 46 MB of faceted STEP.
MAX_TRIANGLES = 20_000


#: triangles of each primitive in a faceted link solid (derive/solids.py: 48 segments round,
#: 96 for a sphere; tests/test_import_step_budget.py holds them to derive's meshes)
FACETED = {"box": 12, "cylinder": 188, "cone": 188, "capsule": 1248, "sphere": 4608}


def visual_triangles(spec: dict, spec_dir: Path) -> int:
    """Triangles of the spec's faceted link solids: those of the binary STLs they use (each
    file counted per use), and of the primitives beside a mesh in one solid (`FACETED`)."""
    total = 0
    for link in spec.get("links", []):
        shapes = link.get("solid", [])
        if not any(shape.get("shape") == "mesh" for shape in shapes):
            continue  # primitives only: exact B-rep faces in the STEP
        for shape in shapes:
            if shape.get("shape") == "mesh":
                header = (spec_dir / shape["file"]).read_bytes()[80:84]
                total += int(np.frombuffer(header, dtype="<u4")[0])
            else:
                total += FACETED.get(shape.get("shape"), 0)
    return total


def step_fits(spec: dict, spec_dir: Path) -> tuple[bool, str]:
    """(whether to write the STEP, the report line saying why not)."""
    count = visual_triangles(spec, spec_dir)
    if count <= MAX_TRIANGLES:
        return True, ""
    megabytes = count * 2.3e3 / 1e6
    return False, (
        f"no STEP assembly (spec step: false): the visual meshes hold {count:,} triangles, a "
        f"faceted STEP of about {megabytes:,.0f} MB (limit {MAX_TRIANGLES:,} triangles)"
    )


def fit(draft: Draft) -> None:
    """The import's step: the STEP left out (`step: false`, one report line) when the
    visual meshes are too large for one (`step_fits`)."""
    fits, why = step_fits(draft.spec, draft.stage)
    if not fits:
        draft.spec["step"] = False
        draft.note_change(why)
        draft.changed()
