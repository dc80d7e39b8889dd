"""Validate the written spec and name the URDF, not the import's staging copy, on a problem.

An import writes its spec into a temporary `.import-XXXX/` folder that is gone when the
user reads the error; a refusal there must name the URDF's own file, line and element (the
link or joint the spec field came from), keeping the spec field in the message.
"""

from __future__ import annotations

import re
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer.read.source import Source
from simkit.spec.validate import load_spec


def check(spec_path: Path, spec: dict, source: Source, renames: dict | None = None) -> None:
    """Load `spec_path` through simkit's own validation; a SpecError is re-raised at the URDF
    element its field comes from (`renames`: names.make_legal's URDF -> spec names)."""
    try:
        load_spec(spec_path, display=spec_path.name)
    except SpecError as exc:
        raise at_urdf(exc, spec, source, renames or {}) from None


def at_urdf(exc: SpecError, spec: dict, source: Source, renames: dict) -> SpecError:
    """`exc` (about the spec) moved to the URDF element its field names."""
    back = {new: old for table in renames.values() for old, new in table.items()}
    robot = source.robot  # the source model (read/model.py): where each item came from
    element = robot.at
    match = re.match(r"(links|joints|frames)\[(\d+)\]", exc.field)
    if match and int(match[2]) < len(spec.get(match[1], [])):
        item = spec[match[1]][int(match[2])]
        name = back.get(item["name"], item["name"])
        tag = "joint" if match[1] == "joints" else "link"
        if match[1] == "joints" and item.get("parent") == spec.get("root"):
            tag, name = "link", back.get(item["child"], item["child"])  # the added root joint
        found = robot.joint(name) if tag == "joint" else robot.link(name)
        element = found.at if found is not None else element
    elif exc.field == "root":
        name = back.get(spec.get("root", ""), spec.get("root", ""))
        found = robot.link(name)
        element = found.at if found is not None else element
    failed = source.fail(element, f"the imported spec's {exc.field}: {exc.message}")
    failed.more = exc.more
    return failed
