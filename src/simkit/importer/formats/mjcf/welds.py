"""An MJCF's `<equality><weld>` between two bodies: a closed loop, carried as one.

A weld between two bodies of the robot (or a body and the world) closes a kinematic loop,
as a URDF link with two parent joints does: each becomes a closure of the shared rule
(importer/translate/loops.py), a spec `loops` weld at the pose the tree gives at home, and
its `equality.NAME` line of listed.py says so (`closed`). A weld between sites, and every
`<connect>` (a ball closure, which a spec cannot hold yet) or joint equality, stay listed
as a kit leaves them out.
"""

from __future__ import annotations

from simkit.importer.read.model import At, Joint

#: mjtEq, mjtObj
WELD, BODY = 1, 1


def closures(model, bodies: list[int], links: dict[int, str]) -> list[Joint]:
    """A fixed closure joint (read/model.py) per body weld of `model` between two of
    `bodies` (or the world, body 0): parent `body1`, child `body2` (held in body1's frame),
    named as the equality (`eqN` without a name), listed as `equality.NAME`; no source line
    (the report names the weld by its listed name)."""
    kept = {0, *bodies}
    out = []
    for e in range(int(model.neq)):
        if int(model.eq_type[e]) != WELD or int(model.eq_objtype[e]) != BODY:
            continue
        ends = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        if not set(ends) <= kept:
            continue
        name = model.eq(e).name or f"eq{e}"
        parent, child = links[ends[0]], links[ends[1]]
        listed = f"equality.{name}"
        out.append(Joint(name, "fixed", At("joint", name), parent, child, listed=listed))
    return out
