"""Whether a floating robot stands on the kit's servos: the import's settle run.

A kit's `legged` check fails a robot whose base, started on the floor at home, sinks on
its position servos (an RL model made to fall, a humanoid on round feet). A format whose
robots may be such (formats/mjcf) refuses them at import, in its own words, from `sinks`.
"""

from __future__ import annotations

from simkit.importer.draft import Draft
from simkit.importer.fixups import collide, settle

#: m the base may sink while the kit's servos hold home (check/legged.py's drift tolerance)
DRIFT = 0.02


def sinks(draft: Draft) -> float | None:
    """m the floating base sinks in the settle run (fixups/settle.py: its collision
    geometry, real masses, servos as the kit's) when over `DRIFT`; None when it stands, or
    the base is fixed, or no start pose is found."""
    if not draft.floating:
        return None
    robot = draft.robot()
    start, follow = collide.posed(robot)
    if start is None:
        return None
    settler = settle.Settler(robot, draft.stage, start, follow)
    height, rest = settler.height(start), settler.run(start)
    drop = height - rest.xyz[2]
    return drop if drop > DRIFT else None
