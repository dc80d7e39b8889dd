"""The formats an import reads: one module (or package) per format, one row each in `FORMATS`.

Each format gives:
- `sniff(path, head)`: whether the file is of this format (`head`: its first 64 KiB without
  comments and processing instructions, read once by `pick` for every format);
- `title(head)`: the name the file gives its robot, or None (the spec's default name);
- `read(shell, options)`: the read `Source` (importer/read/source.py) with its source model
  `robot` (read/model.py, the one model every format gives the translation, numbers as
  numbers: MJCF, SDFormat and USD build it; the URDF and xacro readers leave it None and
  `load` reads their document with formats/urdf/model.py), `kept` (the document as read)
  and `format` set;
- `keep(draft)`: the kept source written beside the spec and the spec's `source` and
  `source_differences` (formats/provenance.py);
- `edits` and `after`: the format's own draft steps, run right after the translation
  (before the shared fix-ups) and after them (importer.steps);
- `locate(folder)` (optional): the model file a folder given as the robot holds (a Gazebo
  model folder's SDF), else None.

`pick` chooses the format once, from the first row whose `sniff` accepts the file; the URDF
row accepts every file, so it comes last. A new format is one module here and one row in
`FORMATS`, plus one module and one row in check/source's `COMPARE` for its source proof.
"""

from __future__ import annotations

import hashlib
import re
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from simkit.importer import read
from simkit.importer.diagnostics import Report
from simkit.importer.formats import finite, mjcf, sdf, urdf, usd, xacro
from simkit.importer.formats.urdf.model import robot_of
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.source import Source


@dataclass(frozen=True)
class Format:
    """One row of `FORMATS`: a format's name and its functions (see the module's text)."""

    name: str
    sniff: Callable[[Path, bytes], bool]
    title: Callable[[bytes], str | None]
    read: Callable[[Source, ReadOptions], Source]
    keep: Callable[[object], None]
    noun: str = "URDF"
    edits: tuple[Callable[[object], None], ...] = ()
    after: tuple[Callable[[object], None], ...] = ()
    #: the model file a folder given as the robot holds (None: the format reads no folders)
    locate: Callable[[Path], Path | None] = lambda folder: None


def _module_row(name: str, module) -> Format:
    return Format(
        name, module.sniff, module.title, module.read, module.keep, module.NOUN, module.EDITS,
        module.AFTER, getattr(module, "locate", lambda folder: None),
    )  # fmt: skip


#: the formats, in the order `pick` tries them (the URDF, which takes any file, last)
FORMATS: tuple[Format, ...] = (
    _module_row("xacro", xacro),
    _module_row("mjcf", mjcf),
    _module_row("sdf", sdf),
    _module_row("usd", usd),
    _module_row("urdf", urdf),
)
BY_NAME = {f.name: f for f in FORMATS}


def head(path: Path) -> bytes:
    """The file's first 64 KiB without comments and processing instructions (b"" when it
    cannot be read: the reader then says why, in one line)."""
    try:
        with path.open("rb") as handle:
            data = handle.read(65536)
    except OSError:
        return b""
    data = re.sub(rb"<!--.*?-->", b"", data, flags=re.S)
    return re.sub(rb"<\?.*?\?>", b"", data, flags=re.S)


@dataclass(frozen=True)
class Picked:
    """The format of a file and the name its file gives the robot (None: none given)."""

    format: Format
    title: str | None
    #: the file to read: the path given, or the model file a model folder names
    path: Path | None = None


def pick(path: Path) -> Picked:
    """The file's format, its head read once (the first row whose `sniff` accepts it); a
    folder is the model file a format's `locate` finds in it (a Gazebo model folder)."""
    if path.is_dir():
        path = next((found for f in FORMATS if (found := f.locate(path))), path)
    first = head(path)
    found = next(f for f in FORMATS if f.sniff(path, first))
    return Picked(found, found.title(first), path)


def load(
    path: Path,
    package_dirs: tuple[Path, ...] = (),
    report: Report | None = None,
    options: ReadOptions | None = None,
    picked: Picked | None = None,
) -> Source:
    """Read `path` with its format's reader (`picked`, else `pick`); `report` takes the
    lenient readings (None: they are refused, as with --strict)."""
    options = options or ReadOptions()
    source = read.shell(path, package_dirs, report, options)
    fmt = (picked or pick(path)).format
    done = fmt.read(source, options)
    try:
        if done.robot is None:  # a URDF document (URDF, xacro): read into the model once
            done.robot = robot_of(done)
        else:  # a model the reader computed: a number that is not finite is refused once
            finite.check(done, done.robot)
    except BaseException:  # refused: what the reader wrote for the translation goes
        for folder in done.scratch:
            shutil.rmtree(folder, ignore_errors=True)
        raise
    for doc in (done, done.kept):
        doc.format, doc.noun = fmt.name, fmt.noun
    done.original = hashlib.sha256(path.read_bytes()).hexdigest()
    done.args = options.args()
    return done
