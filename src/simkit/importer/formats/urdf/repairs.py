"""Links the URDF names but does not declare once: read the way Drake and PyBullet read them.

- **An undeclared mounting frame.** A joint whose parent link is declared nowhere
  (`<parent link="world"/>` without a `world` link, an arm mounted on a `left_hand` of
  another description) mounts the robot on a frame outside it: Drake and PyBullet take
  `world` as the world frame. One undeclared name used only as a parent sits above the root,
  so it becomes an empty link there (the kit's root frame), reported on one line. An
  undeclared name inside the tree (a joint's child) or two of them are still refused by
  `convert.tree`, naming the joint.
- **A link or joint defined twice with identical content** (an include expanded twice)
  is one element: the later copy is dropped, reported on one line. Two different
  definitions of a name are refused by `convert.tree`.
- **A link with two parent joints** (an end effector fixed both to the world and to the
  ankle): a closed loop, which a kit's tree cannot hold. The tree is built from the link's
  first joint in document order; each later one is closed by a weld (spec `loops`) and
  listed in `source_differences` (`joints.J`, formats/provenance.py): the shared rule of
  importer/translate/loops.py, whose first half `second_parents` is (every format's reader
  calls it).
"""

from __future__ import annotations

from simkit.importer.diagnostics import Report
from simkit.importer.read.source import Source


def mounting_frame(source: Source, report: Report) -> str | None:
    """Declare the one undeclared parent link above the root as an empty link (the frame
    the robot is mounted on) and report it; its name, or None when there is none to
    declare (nothing undeclared, or an undeclared name `tree` refuses)."""
    from lxml import etree

    declared = {link.get("name") for link in source.root.findall("link")}
    parents: dict[str, object] = {}  # undeclared parent name -> its first joint
    for joint in source.root.findall("joint"):
        child, parent = joint.find("child"), joint.find("parent")
        if child is not None and child.get("link") not in declared:
            return None  # inside the tree: refused by tree()
        name = None if parent is None else parent.get("link")
        if name and name not in declared:
            parents.setdefault(name, joint)
    if len(parents) != 1:
        return None  # none, or several roots: refused by tree()
    name, joint = next(iter(parents.items()))
    link = etree.Element("link", name=name)
    link.sourceline = joint.sourceline  # reported at the joint that names it
    source.root.insert(0, link)
    report.changed(
        source,
        joint,
        f"parent link '{name}' is not declared: read as the frame the robot is mounted on "
        "(the kit's root frame)",
    )
    return name


def identical_duplicates(source: Source, report: Report) -> None:
    """Drop each later `<link>` or `<joint>` whose name and content repeat an earlier one's
    exactly (attributes, text, children; whitespace and comments aside), one report line
    each; a different definition of the same name is left for `tree` to refuse."""
    for tag in ("link", "joint"):
        first: dict[str, object] = {}
        for element in source.root.findall(tag):
            name = element.get("name")
            if name not in first:
                first[name] = element
            elif _same(first[name], element):
                where = first[name].sourceline
                report.changed(
                    source,
                    element,
                    f"{tag} '{name}' is defined twice with identical content: this copy is "
                    f"ignored (the first is on line {where or '?'})",
                )
                source.root.remove(element)


def _same(a, b) -> bool:
    """Whether two elements have the same tag, attributes, text and children, in order."""
    if a.tag != b.tag or dict(a.attrib) != dict(b.attrib):
        return False
    if (a.text or "").strip() != (b.text or "").strip() or len(a) != len(b):
        return False
    return all(_same(x, y) for x, y in zip(a, b, strict=True))


def second_parents(source: Source, report: Report) -> None:
    """Take each `<joint>` whose child link already has a parent joint earlier in the
    document out of the tree (a closed loop), one report line each, and keep it in
    `source.closures`; the first joint builds the tree."""
    first: dict[str, object] = {}
    for joint in source.root.findall("joint"):
        child = joint.find("child")
        link = None if child is None else child.get("link")
        if link is None:
            continue  # refused by tree(), naming the joint
        if link not in first:
            first[link] = joint
            continue
        said = loop_reason(first[link], link)
        kind = joint.get("type") or "fixed"
        if kind != "fixed":  # a four-bar's pin: the kit holds it rigid (no `connect` yet)
            said += f"; its {kind} motion is locked (a weld holds all six degrees of freedom)"
        report.changed(source, joint, said)
        source.closures.append(joint)
        source.root.remove(joint)


def loop_reason(first, link: str) -> str:
    """The one line on a joint taken out of the tree because `link` hangs from `first`."""
    return (
        f"link '{link}' already has a parent joint '{first.get('name')}' (line "
        f"{first.sourceline or '?'}): a closed loop; the kit keeps the tree from the first "
        "joint and closes the loop with a weld (spec `loops`) at the pose the tree gives "
        "at home"
    )
