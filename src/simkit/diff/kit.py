"""Reading the two kits `simkit diff` compares (folders or zips, possibly hostile: caps and
path confinement from `kitio.kitread`), and writing a read kit back to disk for readers that
need files (`simkit check KIT.zip`)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from simkit.errors import SimkitError
from simkit.kitio import layout
from simkit.kitio.kitread import read_folder_safely, read_zip_safely, robot_json_problem


def _read_zip(path: Path) -> dict[str, bytes]:
    """Files of a kit zip, keyed by path inside the kit (`archive.read_zip`'s top-folder
    rule), read with `kitread`'s caps, or a one-line error for anything else."""
    files = read_zip_safely(path)
    tops = {name.partition("/")[0] if "/" in name else None for name in files}
    if len(tops) == 1 and None not in tops:
        return {name.partition("/")[2]: data for name, data in files.items()}
    return files


def load_kit(path: Path) -> dict[str, bytes]:
    """Files of a kit folder or kit zip, keyed by POSIX path inside the kit. A kit has a
    robot.json at its top; anything else is refused rather than reported as all removed."""
    if path.is_file():
        files = _read_zip(path)
    elif path.is_dir():
        files = read_folder_safely(path)
    else:
        raise SimkitError(f"{path}: no such kit folder or zip")
    if layout.ROBOT_JSON not in files:
        raise SimkitError(f"{path}: not a kit (no {layout.ROBOT_JSON} at its top)")
    why = robot_json_problem(files[layout.ROBOT_JSON])
    if why:
        raise SimkitError(f"{path}: {layout.ROBOT_JSON} {why}")
    return files


def materialize(files: dict[str, bytes], dest: Path) -> Path:
    """Write a kit read by `load_kit` (confined, plain files) under the empty folder `dest`,
    for readers that need files on disk (`simkit check KIT.zip`). A path that is both a file
    and a folder is refused in one line."""
    for rel in sorted(files):
        path = dest / rel
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            with open(path, "xb") as handle:  # never through a link, never over a file
                handle.write(files[rel])
        except OSError as exc:
            raise SimkitError(f"{rel}: cannot be extracted ({exc.strerror or exc})") from None
    return dest


def unpacked(zip_path: Path, files: dict[str, bytes], tmp: Path) -> Path:
    """A kit zip as a build lays it out, under the empty folder `tmp`: the files under
    `NAME_description/` and the zip itself beside them, so the checks that compare the two
    run as on a build (`simkit check KIT.zip`). A robot name unfit for a folder name (any
    character beyond [A-Za-z0-9_]) unpacks as `kit/`, without the zip."""
    name = str(json.loads(files[layout.ROBOT_JSON]).get("name", ""))
    if not re.fullmatch(r"[A-Za-z0-9_]{1,100}", name):
        return materialize(files, tmp / "kit")
    kit = materialize(files, tmp / layout.kit_dir_name(name))
    (tmp / layout.zip_name(name)).write_bytes(zip_path.read_bytes())
    return kit
