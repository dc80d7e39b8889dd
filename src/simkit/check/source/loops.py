"""The source's closed loops against the kit's (robot.json `loops`), read independently.

A source joint whose child link already hangs from an earlier joint (a second parent, in
the source's joint order) closes a loop: the kit keeps the tree from the first joint and
may close the loop with a weld named as the joint (importer/translate/loops.py). Each
robot.json loop of a source joint's name must join that joint's parent and child (kit
names: renamed as listed, a frame by the link it hangs from), and each robot.json loop
no source joint accounts for must be listed (`loops.NAME`). A kit without loops gets no
finding.
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
    closing = second_parents(joints)
    problems = []
    for loop in loops:
        name = loop["name"]
        source = next((n for n in closing if allowed.joints.get(n, n) == name), None)
        if source is None:
            if f"loops.{name}" not in allowed.keys:
                problems.append(f"loop '{name}' closes no loop of the source")
            continue
        ends = [allowed.links.get(n, n) for n in closing[source]]
        ends = [holder.get(n, n) for n in ends]
        if ends != [loop["link1"], loop["link2"]]:
            problems.append(
                f"loop '{name}' joins '{loop['link1']}' and '{loop['link2']}', the source's "
                f"joint '{source}' '{ends[0]}' and '{ends[1]}'"
            )
    return [
        require(
            "source.loops",
            not problems,
            "; ".join(problems)
            or f"{len(loops)} loop(s): each closes a second parent joint of the source",
        )
    ]
