"""Which STEP solid each mesh link gets, decided before anything is emitted (issue 32).

A mesh link whose weld is plainly a closed manifold is faceted as it stands; any other is
checked here (mesh_brep.py: the weld and its repairs, coarser copies, the hull, each whole,
passing BRepCheck and holding the mesh's volume) and the candidate kept is recorded, so the
STEP emitter builds it without checking again. A link with no sound candidate is left out
of the STEP assembly, and robot.json and the kit README say which and why: one link does not
fail the robot. Open CASCADE runs here only for meshes that are not plain, and only when the
kit has a STEP.
"""

from __future__ import annotations

from dataclasses import replace

from simkit.derive.mesh_brep import mesh_plan
from simkit.model.robot import Robot


def derive_step_plans(robot: Robot) -> Robot:
    """`products.step_plans` and `products.step_left_out` (empty for most robots)."""
    if not robot.step:
        return robot
    plans, left_out = {}, []
    for link in robot.links:
        if link.solid is None or not any(s.kind == "mesh" for s in link.shapes):
            continue
        plan, why = mesh_plan(link.solid)
        if plan is None:
            left_out.append({"link": link.name, "why": why})
        elif plan:
            plans[link.name] = list(plan)
    if not plans and not left_out:
        return robot
    products = replace(robot.products, step_plans=plans, step_left_out=left_out)
    return replace(robot, products=products)
