"""The hidden manifest beside a published kit: `out/.NAME.manifest.json`.

It records the digests of the kit folder and of the zip that one build published, so that
`simkit check` and the next build can tell a kit and a zip from two builds apart (a build
killed between the two renames that publish them, `atomic.py`). It is not inside the kit (the
zip holds the kit), holds no time or path, and its bytes depend on the kit's bytes only, so a
rebuild that changes nothing leaves it byte-identical.

    {"format": 1, "kit": "NAME_description", "kit_files": N, "kit_sha256": "...",
     "zip": "NAME-sim-kit.zip", "zip_size": N, "zip_sha256": "..."}

`kit_sha256` is the SHA-256 of the kit's `sha256sum` listing: one line `HEX  PATH\\n` per file,
sorted by POSIX path. Standard library only: the no-op check (`noop.py`) runs before any heavy
import.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from simkit.kitio import layout

FORMAT = 1
SUFFIX = "_description"


def name(robot: str) -> str:
    """`rosie_1000` -> `.rosie_1000.manifest.json` (hidden, beside the kit in --out)."""
    return f".{robot}.manifest.json"


def journal_name(robot: str) -> str:
    """The folder a publish in progress lives in (`atomic.py`); present only mid-publish."""
    return f".{robot}.commit"


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def listing_digest(digests: dict[str, str]) -> str:
    """SHA-256 of the `sha256sum` listing of {POSIX path: file SHA-256}."""
    text = "".join(f"{digests[rel]}  {rel}\n" for rel in sorted(digests))
    return sha256(text.encode("utf-8"))


def make(robot: str, files: dict[str, bytes], zip_data: bytes) -> bytes:
    """The manifest of a kit with `files` (POSIX path -> bytes) and its zip."""
    doc = {
        "format": FORMAT,
        "kit": layout.kit_dir_name(robot),
        "kit_files": len(files),
        "kit_sha256": listing_digest({rel: sha256(data) for rel, data in files.items()}),
        "zip": layout.zip_name(robot),
        "zip_size": len(zip_data),
        "zip_sha256": sha256(zip_data),
    }
    return (json.dumps(doc, indent=1, sort_keys=True) + "\n").encode("utf-8")


def tree(root: Path) -> dict[str, Path]:
    """Every plain file under `root` by POSIX path (symlinks and other entries are left out;
    the check stage refuses them)."""
    found: dict[str, Path] = {}
    for folder, dirs, names in os.walk(root):
        dirs.sort()
        base = Path(folder)
        for entry in names:
            path = base / entry
            if path.is_file() and not path.is_symlink():
                found[path.relative_to(root).as_posix()] = path
    return found


def folder_digest(root: Path) -> tuple[int, str]:
    """(file count, `kit_sha256`) of a kit folder on disk."""
    files = tree(root)
    return len(files), listing_digest({rel: sha256(p.read_bytes()) for rel, p in files.items()})


def robot_of(kit_dir: Path) -> str | None:
    """`.../rosie_1000_description` -> `rosie_1000`; None for a folder not named like a kit."""
    if not kit_dir.name.endswith(SUFFIX) or kit_dir.name == SUFFIX:
        return None
    return kit_dir.name.removesuffix(SUFFIX)


def mismatch(kit_dir: Path) -> str | None:
    """One line saying how the kit folder, its zip and the manifest beside them disagree, or
    None when they agree (or there is no manifest: a kit copied elsewhere). Reads only."""
    robot = robot_of(kit_dir)
    if robot is None:
        return None
    out = kit_dir.parent
    if (out / journal_name(robot)).exists():
        return (
            f"{kit_dir}: a build into {out} was interrupted while publishing this kit and its "
            "zip; run `simkit build` again to finish it"
        )
    path = out / name(robot)
    if not path.is_file():
        return None
    try:
        doc = json.loads(path.read_bytes())
        want_kit, want_zip = doc["kit_sha256"], doc["zip_sha256"]
    except (ValueError, KeyError, TypeError, OSError):
        return f"{path}: unreadable manifest; run `simkit build` again to rewrite it"
    zip_path = out / layout.zip_name(robot)
    kit_ok = kit_dir.is_dir() and folder_digest(kit_dir)[1] == want_kit
    zip_ok = zip_path.is_file() and sha256(zip_path.read_bytes()) == want_zip
    if kit_ok and zip_ok:
        return None
    which = (
        "neither the kit nor the zip"
        if not (kit_ok or zip_ok)
        else ("the kit" if not kit_ok else f"the zip {zip_path.name}")
    )
    return (
        f"{kit_dir}: the kit and {zip_path.name} come from different builds: {which} does not "
        f"match {path.name}; run `simkit build` again to repair"
    )
