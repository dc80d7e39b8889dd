"""A URDF's `<gazebo>`, `<transmission>` and `<ros2_control>` blocks, kept verbatim (issue 15).

Each block becomes one string of spec `urdf_blocks` (its XML as the file has it, after xacro),
which the kit's URDF writes back. Names are the one thing that may change: a link or joint the
importer renamed (names.py) is renamed inside the blocks too; a fixed joint the importer
turned into a frame keeps its name (the frame's `joint`). A block naming a link or joint the
spec does not have cannot be written back faithfully; it is reported on one line and left
out.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from simkit.importer.diagnostics import Report
from simkit.importer.read.source import Source
from simkit.spec.urdf_blocks import TAGS, references


def collect(source: Source) -> list[tuple[object, str]]:
    """(element, XML text) of each top-level block, in document order."""
    from lxml import etree

    return [
        (element, etree.tostring(element, encoding="unicode", with_tail=False))
        for element in source.root
        if isinstance(element.tag, str) and element.tag in TAGS
    ]


def renamed(text: str, links: dict[str, str], joints: dict[str, str]) -> str:
    """`text` with renamed links and joints replaced where the block names them."""
    if not links and not joints:
        return text
    element = ET.fromstring(text)
    reference = element.get("reference")
    if element.tag == "gazebo" and reference:
        element.set("reference", links.get(reference, joints.get(reference, reference)))
    if element.tag in ("transmission", "ros2_control"):
        for joint in element.iter("joint"):
            joint.set("name", joints.get(joint.get("name", ""), joint.get("name", "")))
    return ET.tostring(element, encoding="unicode")


def keep(spec: dict, source: Source, report: Report, found, renames: dict) -> None:
    """Set spec `urdf_blocks` from `found` (`collect`), renamed as the spec was; a block that
    names a link or joint the spec lacks is reported and left out."""
    links = {**renames.get("links", {}), **renames.get("frames", {})}
    joints = renames.get("joints", {})
    link_names = {spec["root"], *(x["name"] for x in [*spec["links"], *spec.get("frames", [])])}
    joint_names = {j["name"] for j in spec["joints"]}
    joint_names |= {f.get("joint") or f"{f['name']}_joint" for f in spec.get("frames", [])}
    kept = []
    for element, text in found:
        try:  # an entity the file's DOCTYPE defines is not defined inside the block
            text = renamed(text, links, joints)
            named = references(ET.fromstring(text))
        except ET.ParseError as exc:
            report.dropped(source, element, f"not well-formed on its own ({exc}): left out")
            continue
        missing = [
            name
            for kind, name in named
            if name not in (joint_names if kind == "joint" else link_names | joint_names)
        ]
        if missing:
            report.dropped(
                source, element, f"names '{missing[0]}', which the spec has no link or joint for"
            )
            continue
        kept.append(text)
    if kept:
        spec["urdf_blocks"] = kept
