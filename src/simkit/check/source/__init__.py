"""The `source` check: the kit is the robot it was imported from, proved per format.

robot.json's `source.format` (the import's formats.FORMATS row) picks the comparison in
`COMPARE`, one module per format, each reading the source with an implementation other than
the importer's reader: urdf.py (yourdfpy; a xacro's kept source is its expansion, a URDF),
mjcf.py (MuJoCo compiles both the source and the kit's MJCF), sdf/ (Drake's SDFormat
parser reads the source and the kit's URDF) and usd/ (usd-core's UsdPhysics parser reads
the composed stage). Each also compares the source with the kit's USD (kit_usd.py). First
the given file's digest is checked against the
one the import recorded, or the original's (shared.py): the file the user imported (a URDF,
a xacro expanded with the recorded args) is read again as the import read it, and must give
the kept file. A kit imported before robot.json named the format is read by its kept
file's suffix (`.xml`: MJCF).
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from types import ModuleType

from simkit.check.findings import Finding
from simkit.check.kit import Kit
from simkit.check.source import mjcf, sdf, urdf, usd
from simkit.check.source.shared import Allowed, digest

__all__ = ["COMPARE", "Allowed", "check_source", "format_of"]

#: robot.json `source.format` -> the module proving the kit is that source: its
#: `compare(kit, path)` (the findings) and `remake(path, args)` (the kept file's bytes made
#: from the original the user imported)
COMPARE: dict[str, ModuleType] = {
    "urdf": urdf,
    "xacro": urdf,
    "mjcf": mjcf,
    "sdf": sdf,
    "usd": usd,
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
    proof = COMPARE[format_of(kit.doc)]
    found, data = digest(kit, kit.source, proof.remake)
    if data == kit.source.read_bytes():
        return found + proof.compare(kit, kit.source)
    with tempfile.TemporaryDirectory(prefix="simkit-source-") as tmp:
        made = Path(tmp) / kit.source.name  # the kept file, made from the original
        made.write_bytes(data)
        return found + proof.compare(kit, made)
