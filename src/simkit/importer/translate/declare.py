"""Links the URDF names but does not declare once: read the way Drake and PyBullet read them.

- **An undeclared mounting frame.** A joint whose parent link is declared nowhere
  (`<parent link="world"/>` without a `world` link, an arm mounted on a `left_hand` of
  another description) mounts the robot on a frame outside it: Drake and PyBullet take
  `world` as the world frame. One undeclared name used only as a parent sits above the root,
  so it becomes an empty link there (the kit's root frame), reported on one line. An
  undeclared name inside the tree (a joint's child) or two of them are still refused by
  `convert.tree`, naming the joint.
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
