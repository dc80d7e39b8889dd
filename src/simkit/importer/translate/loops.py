"""A link with two parent joints (a closed kinematic loop): one rule for every format.

A source whose link hangs from two joints (an end effector fixed both to the arm and to the
world, a four-bar) is a closed loop, which a kit's tree cannot hold. Every format applies
this rule:

- `second_parents` (the translation's first step, on the source model): the tree is built
  from the link's first joint in document order; each later joint is taken out of the
  tree, one report line each, and kept as a closure (`Source.closures`);
- `close` (a step after the names are made legal): each closure becomes a spec `loops`
  entry of type `weld` between the joint's parent and child links (a massless frame's
  holder link in its place), at the pose the tree puts the child in the parent's frame
  at home; `at_home` (after the fix-ups moved home) computes that pose again, so the
  closure holds where the kit starts. The source's joint stays listed in
  `source_differences` (`joints.J`, formats/provenance.py), closed by a weld.

A closure between two links a joint joins already (a second joint between the same two
links) has no loop to close: it is left out with one report line, and so is one whose link
the kit dropped. A format's own closure element (an MJCF `<weld>`, formats/mjcf/welds.py)
is listed in `source_differences` under its key, closed or left out.
"""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np

from simkit.importer.diagnostics import Report
from simkit.importer.draft import Draft
from simkit.importer.read.model import Joint
from simkit.importer.read.source import Source
from simkit.model.kinematics import forward, matrix_rpy
from simkit.spec.names import MAX_NAME, name_problem


def second_parents(source: Source, report: Report) -> None:
    """Take each joint of the source model whose child link already hangs from an earlier
    joint (document order) out of the tree (a closed loop), one report line each, and keep
    it in `source.closures`; the first joint builds the tree."""
    robot = source.robot
    first: dict[str, Joint] = {}
    tree: list[Joint] = []
    for joint in robot.joints:
        link = joint.child
        if link is None or link not in first:  # no child: refused by tree(), naming it
            if link is not None:
                first[link] = joint
            tree.append(joint)
            continue
        said = loop_reason(first[link], link)
        kind = joint.type or "fixed"
        if kind != "fixed":  # a four-bar's pin: the kit holds it rigid (no `connect` yet)
            said += f"; its {kind} motion is locked (a weld holds all six degrees of freedom)"
        report.changed(source, joint.at, said)
        source.closures.append(joint)
    if len(tree) != len(robot.joints):
        source.robot = replace(robot, joints=tuple(tree))


def loop_reason(first: Joint, link: str) -> str:
    """The one line on a joint taken out of the tree because `link` hangs from `first`."""
    return (
        f"link '{link}' already has a parent joint '{first.name}' (line "
        f"{first.at.sourceline or '?'}): a closed loop; the kit keeps the tree from the first "
        "joint and closes the loop with a weld (spec `loops`) at the pose the tree gives "
        "at home"
    )


def close(draft: Draft) -> None:
    """The import's step: each closure of the source a spec `loops` weld (module docstring)."""
    renamed = {k: dict(v) for k, v in draft.renames.items()}
    holders = _holders(draft.spec)
    names = {j["name"] for j in draft.spec["joints"]}
    loops = []
    for joint in draft.source.closures:  # source model joints (read/model.py)
        ends = []
        for old in (joint.parent, joint.child):
            new = renamed.get("links", {}).get(old) or renamed.get("frames", {}).get(old) or old
            ends.append(holders.get(new, new))
        link1, link2 = ends
        why = _unclosable(draft.spec, link1, link2)
        listed = joint.listed  # a format's own element (an MJCF weld), listed so
        if why:
            draft.report.dropped(draft.source, joint.at, f"a closed loop with {why}")
            if listed:
                draft.listed.append((listed, f"left out: {why}"))
            continue
        name = _free(renamed.get("joints", {}).get(joint.name) or joint.name, names)
        names.add(name)
        loops.append({"name": name, "type": "weld", "link1": link1, "link2": link2})
        if listed:
            said = f"closed by a weld (spec `loops` '{name}') at the pose the tree gives at home"
            draft.report.changed(draft.source, joint.at, f"'{link2}' welded to '{link1}': {said}")
            draft.listed.append((listed, said))
    if loops:
        draft.spec["loops"] = loops
        draft.changed()
        at_home(draft)


def at_home(draft: Draft) -> None:
    """The import's step: each spec loop's pose set to link2's pose in link1's frame at
    home, from the tree's forward kinematics (6 significant digits)."""
    if not draft.spec.get("loops"):
        return
    robot = draft.robot()
    home = dict(robot.poses).get("home")
    poses = forward(robot, home)
    for loop in draft.spec["loops"]:
        pose = np.linalg.inv(poses[loop["link1"]]) @ poses[loop["link2"]]
        loop["xyz"] = [_num(v) for v in pose[:3, 3]]
        loop["rpy"] = [_num(v) for v in matrix_rpy(pose[:3, :3])]
    draft.changed()


def _num(value: float) -> float:
    """A pose number as the spec keeps it: 10 significant digits, no negative zero."""
    return float(f"{value:.10g}") + 0.0


def _holders(spec: dict) -> dict[str, str]:
    """Each spec frame's link (or the root): a loop that ends on a frame ends on it."""
    parent = {f["name"]: f["parent"] for f in spec.get("frames", [])}
    out = {}
    for name in parent:
        node = name
        while node in parent:
            node = parent[node]
        out[name] = node
    return out


def _unclosable(spec: dict, a: str | None, b: str | None) -> str:
    """Why no loop joins `a` and `b` ("" when one does): two different links (or the root)
    that no joint joins already."""
    known = {link["name"] for link in spec["links"]} | {spec.get("root")}
    missing = [n for n in (a, b) if n not in known]
    if missing:
        return f"'{missing[0]}', which is no link of the kit: no loop to close"
    if a == b:
        return f"'{a}' itself: no loop to close"
    if spec.get("floating_base") and spec.get("root") in (a, b):
        return f"the world '{spec.get('root')}', which a floating base does not hang from"
    if any({j["parent"], j["child"]} == {a, b} for j in spec["joints"]):
        return f"'{a}' and '{b}' joined by a joint already: no loop to close"
    return ""


def _free(name: str, taken: set[str]) -> str:
    """`name` in the spec's name grammar (other characters `_`, a leading digit after an
    `n`), or `name_loop`, `name_loop2`, ... where a joint or loop has it."""
    if name_problem(name):
        name = re.sub(r"[^A-Za-z0-9_]", "_", name) or "loop"
        name = (name if not name[0].isdigit() else f"n{name}")[: MAX_NAME - 8]
    if name not in taken:
        return name
    out, n = f"{name}_loop", 2
    while out in taken:
        out, n = f"{name}_loop{n}", n + 1
    return out
