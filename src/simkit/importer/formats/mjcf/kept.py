"""The kept source of an MJCF import: the model file as read, byte for byte
(`NAME.source.xml`), and every other file it read (includes, meshes, textures) as
`NAME.source.assets/SHA256.EXT`, their digests in the spec's `source` (`assets`: path
relative to the model's folder -> SHA-256). The source check (check/source/mjcf.py) lays
them out again and compiles them in MuJoCo, or reads them beside a given MODEL.xml.
"""

from __future__ import annotations

import hashlib
from pathlib import PurePosixPath

from simkit.importer.formats import provenance
from simkit.importer.formats.mjcf.reader import MjcfSource


def source_name(spec: dict) -> str:
    """The kept MJCF's file name, beside the spec."""
    return f"{spec['name']}.source.xml"


def keep(draft, source: MjcfSource) -> dict:
    """Write the kept files into the staging folder; the spec's `source` entry."""
    name = source_name(draft.spec)
    main = source.files[_main_key(source)]
    (draft.stage / name).write_bytes(main)
    assets: dict[str, str] = {}
    folder = draft.stage / f"{draft.spec['name']}.source.assets"
    for rel, data in sorted(source.files.items()):
        if rel == _main_key(source):
            continue
        digest = hashlib.sha256(data).hexdigest()
        assets[rel] = digest
        folder.mkdir(exist_ok=True)
        (folder / f"{digest}{PurePosixPath(rel).suffix.lower()}").write_bytes(data)
    entry = provenance.entry(draft, name, main)
    if assets:
        entry["assets"] = assets
    return entry


def _main_key(source: MjcfSource) -> str:
    return source.path.name
