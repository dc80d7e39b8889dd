"""The kept source of a USD import: the root layer as read, byte for byte
(`NAME.source.usd|usda|usdc`), and every other layer the stage composed as
`NAME.source.assets/SHA256.EXT`, their digests in the spec's `source` (`assets`: path
relative to the root layer's folder -> SHA-256). The source check (check/source/usd/) lays
them out again with their relative paths and composes the stage from them.
"""

from __future__ import annotations

import hashlib
from pathlib import PurePosixPath

from simkit.importer.formats import provenance


def source_name(spec: dict, suffix: str) -> str:
    """The kept root layer's file name, beside the spec."""
    return f"{spec['name']}.source{suffix.lower()}"


def keep(draft, source) -> dict:
    """Write the kept layers into the staging folder; the spec's `source` entry."""
    main_key = source.path.name
    main = source.files[main_key]
    name = source_name(draft.spec, source.path.suffix)
    (draft.stage / name).write_bytes(main)
    assets: dict[str, str] = {}
    folder = draft.stage / f"{draft.spec['name']}.source.assets"
    for rel, data in sorted(source.files.items()):
        if rel == main_key:
            continue
        digest = hashlib.sha256(data).hexdigest()
        assets[rel] = digest
        folder.mkdir(exist_ok=True)
        (folder / f"{digest}{PurePosixPath(rel).suffix.lower()}").write_bytes(data)
    entry = provenance.entry(draft, name, main)
    if assets:
        entry["assets"] = assets
    return entry
