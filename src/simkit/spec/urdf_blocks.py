"""Spec `urdf_blocks`: URDF elements a kit carries over verbatim (issue 15).

An imported URDF's `<gazebo>`, `<transmission>` and `<ros2_control>` blocks hold what
simkit does not model (Gazebo plugins and materials, gear ratios, hardware interfaces);
users' launch files depend on them, so `simkit import` keeps each one as its XML text and the
URDF emitter writes them back after the links and joints, in spec order. Validation: each
block is one well-formed element of those tags, and every link or joint it names exists.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterator

TAGS = ("gazebo", "transmission", "ros2_control")
Problem = tuple[tuple, str]


def parse(text: str) -> ET.Element:
    """The block's element (ET.ParseError on malformed XML)."""
    return ET.fromstring(text)


def references(element: ET.Element) -> list[tuple[str, str]]:
    """(kind, name) of each link or joint a block names: `<gazebo reference=...>` (a link or
    a joint), `<joint name=...>` inside a transmission or ros2_control block."""
    out = []
    if element.tag == "gazebo" and element.get("reference"):
        out.append(("link or joint", element.get("reference", "")))
    if element.tag in ("transmission", "ros2_control"):
        out += [("joint", j.get("name", "")) for j in element.iter("joint") if j.get("name")]
    return out


def problems(spec, links: set[str], joints: set[str]) -> Iterator[Problem]:
    """Blocks that do not parse, have another tag, or name a missing link or joint."""
    for i, text in enumerate(spec.urdf_blocks):
        where = ("urdf_blocks", i)
        try:
            element = parse(text)
        except ET.ParseError as exc:
            yield where, f"not well-formed XML: {exc}"
            continue
        if element.tag not in TAGS:
            yield where, f"<{element.tag}> is not one of <{'>, <'.join(TAGS)}>"
            continue
        if not text.startswith(f"<{element.tag}"):  # an XML declaration, DOCTYPE or comment
            yield where, f"must start with <{element.tag}> (it goes inside the URDF's <robot>)"
            continue
        if element.tag == "ros2_control" and spec.ros2_control is not None:
            yield where, "a <ros2_control> block and a `ros2_control:` section both write one"
        for kind, name in references(element):
            known = joints if kind == "joint" else links | joints
            if name not in known:
                yield where, f"<{element.tag}> names {kind} '{name}', which the spec lacks"


def digest(text: str) -> str:
    """SHA-256 of the block's canonical XML (C14N 2.0, whitespace at text edges stripped,
    namespace prefixes renamed in order of use): the same XML gives the same digest however
    it is indented and whatever its prefixes are called."""
    import hashlib

    canonical = ET.canonicalize(xml_data=text, strip_text=True, rewrite_prefixes=True)
    return hashlib.sha256(canonical.encode("utf-8")).hexdigest()


def summary(text: str) -> dict:
    """robot.json's entry for one block: its tag, the links and joints it names, its digest."""
    element = parse(text)
    return {
        "tag": element.tag,
        "names": [name for _kind, name in references(element)],
        "sha256": digest(text),
    }
