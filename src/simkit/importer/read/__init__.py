"""Reading, shared by every format: the read document (`Source`, source.py), package and
file lookup (packages.py), lenient forms (lenient.py), the user's reading options
(options.py) and the safe expression evaluator (safe_eval.py).

The formats themselves (what a file is, its reader, its kept copy) are importer/formats,
one module per format behind one table; `shell` is the empty `Source` each reader fills.
"""

from __future__ import annotations

from pathlib import Path

from simkit.errors import SpecError
from simkit.importer.diagnostics import Report
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.packages import PackageMap
from simkit.importer.read.source import Source


def shell(
    path: Path, package_dirs: tuple[Path, ...], report: Report | None, options: ReadOptions
) -> Source:
    """The `Source` of `path` before a reader parses it: its PackageMap (package://
    lookup, --allow-read folders) and the report; one line when there is no such file."""
    if not path.is_file():
        raise SpecError(str(path), None, "file", "no such file")
    packages = PackageMap(path, tuple(package_dirs), tuple(options.allow_read))
    return Source(path, None, packages, report)
