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
  importer/translate/loops.py, on the source model of every format.
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
