"""A read document (`Source`) and its mesh URIs resolved (package://, file://, relative).

Errors are one line each, naming the file, the line and the element (`errors.SpecError`).
Messy but common forms are read leniently, one report line each (`Source.lenient`), and
refused with `--strict` (docs/importing.md, "Lenient reading"). The report is the one
diagnostic channel of the read (Drake's DiagnosticPolicy); a PackageMap owns paths. The
readers that make a Source, one per format, are in importer/formats (one table).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer.diagnostics import Diagnostic, Report, describe, line_of
from simkit.importer.read.lenient import Position
from simkit.importer.read.model import Joint, Robot
from simkit.importer.read.packages import MissingMesh, PackageMap

__all__ = ["MissingMesh", "Position", "Source", "describe", "line_of", "resolve_uri"]


@dataclass
class Source:
    """The parsed document: its root element, where it came from, how to find packages,
    and the report its lenient readings go to (None: refuse them). A format's reader
    (importer/formats) fills the rest: `format` (its row in formats.FORMATS), `kept` (the
    document as read, before any repair or rewrite: what the kit is compared with),
    `original` and `args` (the imported file's digest, the --xacro-arg values), `base`
    ((floating, why) when the format itself says whether the base floats, an MJCF's free
    joint) and `scratch` (folders the translation reads from, removed after the import)."""

    path: Path
    root: object  # lxml.etree._Element
    packages: PackageMap
    report: Report | None = None
    format: str = ""
    #: SHA-256 of the file the user imported, and the --xacro-arg values read with it
    original: str = ""
    args: dict[str, str] = field(default_factory=dict)
    kept: Source | None = None
    base: tuple[bool, str] | None = None
    scratch: list[Path] = field(default_factory=list)
    #: the format's own word for the file, in report lines ("URDF", "MJCF")
    noun: str = "URDF"
    #: joints taken out of the tree because their child already hangs from an earlier one
    #: (a closed loop, importer/translate/loops.py): each becomes a spec `loops` weld
    closures: list[Joint] = field(default_factory=list)
    #: the source model the translation reads (read/model.py `Robot`), numbers as numbers:
    #: set once the format's reader is done (formats.load)
    robot: Robot | None = None

    @property
    def a_noun(self) -> str:
        """The noun with its article as it is spoken ("a URDF", "an MJCF")."""
        return f"{'an' if self.noun[:1] in 'AEFHILMNORSX' else 'a'} {self.noun}"

    def fail(self, element, message: str) -> SpecError:
        """A one-line error at `element` (file, line, element tag and name): the refusal of
        an error record."""
        return Diagnostic.at(self, element, "refused", message, "error").error()

    def lenient(self, element, message: str) -> None:
        """A form read the way the field's parsers read it: one report line (changed), or
        the error `--strict` asks for."""
        if self.report is None:
            raise self.fail(element, f"{message} (--strict refuses it)")
        self.report.lenient(self, element, message)

    def note(self, element, message: str) -> None:
        """A report line for something the user asked for (a --xacro-arg value used)."""
        if self.report is not None:
            self.report.changed(self, element, message)


def resolve_uri(source: Source, element, uri: str) -> Path:
    """The file a mesh `filename` names (PackageMap); each fallback is one report line.
    MissingMesh when no file is found, SpecError when refused or ambiguous."""
    done = len(source.packages.notes)
    where = (str(source.path), line_of(element), describe(element))
    path = source.packages.resolve(uri, where)
    for message in source.packages.notes[done:]:
        source.note(element, message)
    return path
