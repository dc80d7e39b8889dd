"""Links that overlap at the source's own home (issue 42, class 7).

MoveIt Setup Assistant disables the pairs in collision at the robot's default pose
("Default"): the source's authors let them overlap (a hip yaw and a hip pitch link joined
through a small roll link, 4 mm into each other at zero). Where the home search
(home.py, stance.py) leaves such a pair touching, the import excludes it as well: the pair
goes to the spec's `contact_excludes` (the kit's MJCF `<exclude>`, USD filtered pairs and
SRDF disabled pairs), one report line, and `source_differences` (`contact_excludes.A.B`,
kit names). A pair that touches only away from home is not excluded: the kit keeps checking
it. The model is the kit's collision as the search sees it (collide.covered_shapes, the
adjacent and always-touching pairs and the source's excludes left out); touching is closer
than collide.TOUCH.
"""

from __future__ import annotations

import numpy as np

from simkit.importer.fixups.collide import (
    always_touching,
    contacts,
    covered_shapes,
    model_xml,
    posed,
)
from simkit.importer.fixups.scratch import compiled


def at_home(robot, base_dir, first) -> list[tuple[str, str]]:
    """Link pairs (sorted names) touching both at the source's home `first` and at the
    robot's home (the pose the search chose; the same when it found no free one)."""
    start, follow = posed(robot)
    if start is None:
        return []
    always = always_touching(robot, base_dir, start, follow, covered_shapes)
    xml = model_xml(robot, base_dir, always, covered_shapes)
    model, data, adr = compiled(xml, robot.movable_joints)
    there = contacts(model, data, adr, np.asarray(first, dtype=float))
    return sorted(there & contacts(model, data, adr, start))


def exclude(draft, first: list[float]) -> None:
    """Exclude the pairs that overlap at the source's home `first` and at the chosen home
    (at_home), with one report line and their `source_differences` entries."""
    pairs = at_home(draft.robot(), draft.stage, first)
    if not pairs:
        return
    known = {tuple(p) for p in draft.spec.get("contact_excludes", [])}
    draft.spec["contact_excludes"] = [list(p) for p in sorted(known | set(pairs))]
    draft.changed()
    reason = (
        "in contact at the source's home, where the source lets them overlap: excluded from "
        "contact as MoveIt Setup Assistant's 'Default' pairs"
    )
    for a, b in pairs:
        draft.listed.append((f"contact_excludes.{a}.{b}", reason))
    shown = ", ".join(f"{a} / {b}" for a, b in pairs)
    draft.note(f"{len(pairs)} link pair(s) {reason}: {shown}")
