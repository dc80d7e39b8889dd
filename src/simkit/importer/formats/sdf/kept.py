"""The kept source of an SDFormat import: the model file as read, byte for byte
(`NAME.source.sdf`), and every other file it read (includes, model.config, meshes) as
`NAME.source.assets/SHA256.EXT`; the spec's `source.assets` records them all (path relative
to the model path, the model folder's parent -> SHA-256; the model file is the one whose
digest is `source.sha256`: its entry gives its place). The source check
(check/source/sdf/) lays them out again, each top folder a model (`model://NAME`), and
reads them with Drake.
"""

from __future__ import annotations

import hashlib
from pathlib import PurePosixPath

from simkit.importer.formats import provenance


def keep(draft, source) -> dict:
    """Write the kept files into the staging folder; the spec's `source` entry."""
    files = source.files
    main_key = files.key(files.main)
    name = f"{draft.spec['name']}.source.sdf"
    main = files.files[main_key]
    (draft.stage / name).write_bytes(main)
    assets: dict[str, str] = {}
    folder = draft.stage / f"{draft.spec['name']}.source.assets"
    for rel, data in sorted(files.files.items()):
        digest = hashlib.sha256(data).hexdigest()
        assets[rel] = digest
        if rel == main_key:
            continue  # kept as NAME.source.sdf: recorded for its place only
        folder.mkdir(exist_ok=True)
        (folder / f"{digest}{PurePosixPath(rel).suffix.lower()}").write_bytes(data)
    entry = provenance.entry(draft, name, main)
    entry["assets"] = assets
    return entry
