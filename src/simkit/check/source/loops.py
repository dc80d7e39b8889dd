"""The source's closed loops against the kit's (robot.json `loops`), read independently.

A source joint whose child link already hangs from an earlier joint (a second parent, in
the source's joint order) closes a loop: the kit keeps the tree from the first joint and
closes the loop with a weld from the joint's parent to its child
(importer/translate/loops.py). Each robot.json loop must join the parent and child of such
a source joint (kit names: renamed as listed, a frame by the link it hangs from), or be
listed (`loops.NAME`). A kit without loops gets no finding.
"""

from __future__ import annotations

from simkit.check.findings import Finding, require
from simkit.check.source.shared import Allowed


def second_parents(joints) -> dict[str, tuple[str, str]]:
    """{joint name: (parent, child)} of each joint whose child has an earlier parent joint;
    `joints` have `name`, `parent` and `child` (yourdfpy's)."""
    parented: set[str] = set()
    out = {}
    for joint in joints:
        if joint.child in parented:
            out[joint.name] = (joint.parent, joint.child)
        parented.add(joint.child)
    return out


def compare(joints, doc: dict, allowed: Allowed) -> list[Finding]:
    """`source.loops`: robot.json's loops against the source's second parent joints."""
    loops = doc.get("loops") or []
    if not loops:
        return []
    links = {link["name"] for link in doc.get("links", [])}
    holder = {  # robot.json's frames hold every link's too: only the others hang from one
        name: f.get("parent", name)
        for name, f in (doc.get("frames") or {}).items()
        if name not in links
    }
    closing = {
        tuple(holder.get(allowed.links.get(n, n), allowed.links.get(n, n)) for n in ends)
        for ends in second_parents(joints).values()
    }
    problems = [
        f"loop '{loop['name']}' joins '{loop['link1']}' and '{loop['link2']}': no second "
        "parent joint of the source does"
        for loop in loops
        if (loop["link1"], loop["link2"]) not in closing
        and f"loops.{loop['name']}" not in allowed.keys
    ]
    return [
        require(
            "source.loops",
            not problems,
            "; ".join(problems)
            or f"{len(loops)} loop(s): each closes a second parent joint of the source",
        )
    ]


#: mjtEq, mjtObj
WELD, BODY = 1, 1


def compare_mjcf(pairs, doc: dict) -> list[Finding]:
    """`source.loops` of an MJCF source: each robot.json loop is a body `<weld>` of the
    source between the same bodies (the kit's names; the root: MuJoCo's world), or listed
    (`loops.NAME`). `pairs`: check/source/mjcf.py's source -> kit pairing."""
    loops = doc.get("loops") or []
    if not loops:
        return []
    s, k = pairs.source, pairs.kit
    welds = set()
    for e in range(int(s.neq)):
        if int(s.eq_type[e]) != WELD or int(s.eq_objtype[e]) != BODY:
            continue
        ends = (int(s.eq_obj1id[e]), int(s.eq_obj2id[e]))
        ids = [pairs.kit_id("body", s.body(b).name) if b else 0 for b in ends]
        if min(ids) >= 0:
            welds.add(tuple(k.body(i).name for i in ids))
    links = {link["name"] for link in doc.get("links", [])}
    problems = [
        f"loop '{loop['name']}' joins '{loop['link1']}' and '{loop['link2']}': no body weld "
        "of the source does"
        for loop in loops
        if tuple(n if n in links else "world" for n in (loop["link1"], loop["link2"])) not in welds
        and not pairs.listed(f"loops.{loop['name']}")
    ]
    return [
        require(
            "source.loops",
            not problems,
            "; ".join(problems) or f"{len(loops)} loop(s): each is a body weld of the source",
        )
    ]
