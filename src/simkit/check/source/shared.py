"""What every format's source proof shares: robot.json's listed differences (`Allowed`),
the tolerances, and the digest of the given source file."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit

#: relative tolerance: the kit carries 10 significant digits (kitio/fmt.py); a hand-typed
#: source rarely more. Far below any real change (an axis turned, a mass 10 % off).
REL = 1e-6
#: m: absolute floor for lengths; kg m^2 floor for inertia terms is REL x the largest moment
ABS_LENGTH = 1e-9
#: failures named per finding category before "and N more"
SHOWN = 20


@dataclass
class Allowed:
    """robot.json's `source_differences`: allowed keys and the source -> kit renames."""

    keys: set[str] = field(default_factory=set)
    links: dict[str, str] = field(default_factory=dict)
    joints: dict[str, str] = field(default_factory=dict)

    @staticmethod
    def of(doc: dict) -> Allowed:
        """From robot.json (or any dict with `source_differences`)."""
        out = Allowed()
        for item in doc.get("source_differences", []):
            what = str(item.get("what", ""))
            out.keys.add(what)
            kind, _, rest = what.partition(".")
            name, _, attr = rest.rpartition(".")
            if attr == "name" and isinstance(item.get("kit"), str) and kind in ("links", "joints"):
                getattr(out, kind)[name] = item["kit"]
        return out


def digest(kit: Kit, path: Path) -> list[Finding]:
    """The source file is the one the import recorded (robot.json `source.sha256`)."""
    recorded = (kit.doc.get("source") or {}).get("sha256")
    if recorded is None:
        return []
    actual = hashlib.sha256(path.read_bytes()).hexdigest()
    return [
        require(
            "source.digest",
            actual == recorded,
            f"{path.name} is the file the import recorded (sha256 {recorded[:12]}...)"
            if actual == recorded
            else f"{path.name} was changed after the import: sha256 {actual[:12]}..., "
            f"robot.json records {recorded[:12]}...",
        )
    ]
