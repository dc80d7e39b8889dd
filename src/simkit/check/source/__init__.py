"""The `source` check: the kit is the robot it was imported from, proved per format.

robot.json's `source.format` (the import's formats.FORMATS row) picks the comparison in
`COMPARE`, one module per format, each reading the source with an implementation other than
the importer's reader: urdf.py (yourdfpy; a xacro's kept source is its expansion, a URDF)
and mjcf.py (MuJoCo compiles both the source and the kit's MJCF). Both also compare the
source with the kit's USD (kit_usd.py). First the given file's digest is checked against the
one the import recorded (shared.py). A kit imported before robot.json named the format is
read by its kept file's suffix (`.xml`: MJCF).
"""

from __future__ import annotations

from collections.abc import Callable

from simkit.check.findings import Finding
from simkit.check.kit import Kit
from simkit.check.source import mjcf, urdf
from simkit.check.source.shared import Allowed, digest

__all__ = ["COMPARE", "Allowed", "check_source", "format_of"]

#: robot.json `source.format` -> the comparison of the kit with its source
COMPARE: dict[str, Callable[[Kit], list[Finding]]] = {
    "urdf": urdf.compare,
    "xacro": urdf.compare,
    "mjcf": mjcf.compare,
}


def format_of(doc: dict) -> str:
    """The source's format as robot.json records it (`source.format`), else from the kept
    file's suffix (a kit imported before the format was recorded)."""
    source = doc.get("source") or {}
    recorded = source.get("format")
    if isinstance(recorded, str) and recorded in COMPARE:
        return recorded
    return "mjcf" if str(source.get("file", "")).lower().endswith(".xml") else "urdf"


def check_source(kit: Kit) -> list[Finding]:
    """The comparison, when the build or `simkit check --source` gave a source file; no
    findings otherwise (a hand-written spec has no source)."""
    if kit.source is None:
        return []
    return digest(kit, kit.source) + COMPARE[format_of(kit.doc)](kit)
