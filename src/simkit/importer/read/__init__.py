"""Readers: a robot file to a `Source` (read/source.py), one reader per format.

`READERS` maps what the file is (`kind_of`) to its reader (MJCF: MuJoCo itself,
read/mjcf.py); `load` builds the PackageMap and picks the reader. Each reader takes a
`Source` shell (path, packages, report; no root yet) and the user's `ReadOptions`, and
returns it with its document parsed. A new format is one module here and one row in the
table (Drake's `detail_*_parser` per format).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer.diagnostics import Report
from simkit.importer.read import mjcf, urdf, xacro
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.packages import PackageMap
from simkit.importer.read.source import Source

#: a reader: the shell `Source` and the options to the parsed `Source`
Reader = Callable[[Source, ReadOptions], Source]

#: what the file is -> its reader
READERS: dict[str, Reader] = {"urdf": urdf.read, "xacro": xacro.read, "mjcf": mjcf.read}


def kind_of(path: Path) -> str:
    """What the file is: `xacro` by its name (`.xacro`, `.urdf.xacro`), `mjcf` by its
    `<mujoco>` root element, else `urdf`."""
    if path.suffix == ".xacro" or path.name.endswith(".urdf.xacro"):
        return "xacro"
    return "mjcf" if mjcf.is_mjcf(path) else "urdf"


def load(
    path: Path,
    package_dirs: tuple[Path, ...] = (),
    report: Report | None = None,
    options: ReadOptions | None = None,
) -> Source:
    """Read `path` with the reader for its kind (a `.xacro` is expanded safely unless
    trusted); `report` takes the lenient readings (None: they are refused, as with
    --strict)."""
    options = options or ReadOptions()
    if not path.is_file():
        raise SpecError(str(path), None, "file", "no such file")
    packages = PackageMap(path, tuple(package_dirs), tuple(options.allow_read))
    shell = Source(path, None, packages, report)
    return READERS[kind_of(path)](shell, options)
