"""Reading kits that may be hostile (`simkit diff`, `simkit check`): size caps, no encrypted
entries, no path or symlink leaving the kit, and a robot.json of the expected shape. Every
refusal is one `SimkitError` line.
"""

from __future__ import annotations

import json
import os
import posixpath
import zipfile
from pathlib import Path

from simkit.errors import SimkitError

MAX_ENTRY = 64 << 20  # bytes per file: the largest kit file (a USD crate) is a few MB
MAX_TOTAL = 512 << 20  # bytes in all
MAX_ENTRIES = 20_000


def inside(rel: str) -> bool:
    """True for a relative POSIX path that stays inside its folder."""
    if not rel or rel.startswith("/") or "\\" in rel or ":" in rel.partition("/")[0]:
        return False
    norm = posixpath.normpath(rel)
    return norm not in (".", "..") and not norm.startswith("../")


def read_zip_safely(path: Path) -> dict[str, bytes]:
    """Files of a zip keyed by their entry names, refusing encrypted, oversized or escaping
    entries (the sizes are enforced while reading, not trusted from the header)."""
    try:
        with zipfile.ZipFile(path) as archive:
            infos = [i for i in archive.infolist() if not i.is_dir()]
            if len(infos) > MAX_ENTRIES:
                raise SimkitError(f"{path}: more than {MAX_ENTRIES} entries")
            files: dict[str, bytes] = {}
            total = 0
            for info in infos:
                name = info.filename
                if not inside(name):
                    raise SimkitError(f"{path}: entry {name!r} leaves the kit")
                if info.flag_bits & 0x1:
                    raise SimkitError(f"{path}: entry {name!r} is encrypted")
                if name in files:
                    raise SimkitError(f"{path}: entry {name!r} appears twice")
                with archive.open(info) as handle:
                    data = handle.read(MAX_ENTRY + 1)
                if len(data) > MAX_ENTRY:
                    raise SimkitError(f"{path}: entry {name!r} is over {MAX_ENTRY >> 20} MiB")
                total += len(data)
                if total > MAX_TOTAL:
                    raise SimkitError(f"{path}: more than {MAX_TOTAL >> 20} MiB unpacked")
                files[name] = data
    except SimkitError:
        raise
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, ValueError, EOFError) as exc:
        raise SimkitError(f"{path}: not a kit zip ({' '.join(str(exc).split())})") from None
    except (NotImplementedError, RuntimeError) as exc:  # unsupported compression, password
        raise SimkitError(f"{path}: unreadable zip entry ({exc})") from None
    return files


def read_folder_safely(root: Path, read: bool = True) -> dict[str, bytes]:
    """Files under a kit folder, refusing symlinks, special files and oversized files
    (`read=False`: only the refusals, every value empty)."""
    files: dict[str, bytes] = {}
    total = 0
    for folder, dirs, names in os.walk(root, followlinks=False):
        dirs[:] = [d for d in dirs if d != "__pycache__"]
        for name in sorted(dirs + names):
            path = Path(folder) / name
            rel = path.relative_to(root).as_posix()
            if path.is_symlink():
                raise SimkitError(f"{root}: {rel} is a symlink; a kit holds plain files only")
            if name in names:
                if not path.is_file():
                    raise SimkitError(f"{root}: {rel} is not a regular file")
                size = path.stat().st_size
                total += size
                if size > MAX_ENTRY:
                    raise SimkitError(
                        f"{root}: {rel} is over the kit size cap: {size / 2**20:.1f} MiB, "
                        f"{MAX_ENTRY >> 20} MiB per file"
                    )
                if total > MAX_TOTAL:
                    raise SimkitError(
                        f"{root}: {rel} is over the kit size cap: the kit holds "
                        f"{total / 2**20:.1f} MiB with it, {MAX_TOTAL >> 20} MiB in all"
                    )
                files[rel] = path.read_bytes() if read else b""
        if len(files) > MAX_ENTRIES:
            raise SimkitError(f"{root}: more than {MAX_ENTRIES} files")
    return files


#: robot.json keys a reader relies on, with the JSON type each must have
SHAPE = {
    "name": str,
    "joints": list,
    "fixed_joints": list,
    "links": list,
    "frames": dict,
    "files": dict,
}


def robot_json_problem(data: bytes) -> str | None:
    """Why `data` is not a robot.json simkit can read, or None."""
    try:
        doc = json.loads(data)
    except (ValueError, RecursionError) as exc:
        return f"is not valid JSON ({' '.join(str(exc).split())[:120]})"
    if not isinstance(doc, dict):
        return f"must be a JSON object, not a {type(doc).__name__}"
    for key, kind in SHAPE.items():
        if key in doc and not isinstance(doc[key], kind):
            return f"'{key}' must be a JSON {kind.__name__.replace('dict', 'object')}"
    if not isinstance(doc.get("name"), str):
        return "'name' is missing"
    for key in ("joints", "fixed_joints", "links"):
        for i, item in enumerate(doc.get(key, [])):
            if not isinstance(item, dict) or not isinstance(item.get("name"), str):
                return f"'{key}[{i}]' must be an object with a string 'name'"
    for key, value in doc.get("files", {}).items():
        if not isinstance(value, str) or not inside(value):
            return f"'files.{key}' must be a path inside the kit"
    return None
