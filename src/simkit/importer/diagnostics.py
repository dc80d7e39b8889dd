"""What an import kept, estimated and left out: one record per fact, never silent.

Every step says what it did through one `Report` (Drake's DiagnosticPolicy): a `Diagnostic`
record (file, line, element, kind, message, severity) per fact, in the order the steps found
them. The `Policy` decides whether a fact `--strict` may refuse is a warning (reported) or
an error (refused); the report lines, the spec's header comment and provenance's
`source_differences` are all made from the same records (provenance reads records, never
the text). This module is the importer's lowest layer: it knows elements only by their
`sourceline`, `tag` and `get` (lxml elements and read.lenient.Position alike).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal, Protocol

from simkit.errors import SpecError

#: note: reported, never refused; warning: reported, refused with --strict; error: refused
Severity = Literal["note", "warning", "error"]


class Located(Protocol):
    """What a diagnostic needs of the document it is about (read.source.Source)."""

    path: Path


def line_of(element) -> int | None:
    """Source line of an lxml element (None when unknown)."""
    line = getattr(element, "sourceline", None)
    return int(line) if line else None


def describe(element) -> str:
    """`tag` or `tag[name]` (URDF elements are named by their `name` attribute)."""
    if element is None:
        return "robot"
    name = element.get("name") if hasattr(element, "get") else None
    return f"{element.tag}[{name}]" if name else str(element.tag)


@dataclass(frozen=True)
class Diagnostic:
    """One fact about the source: `file` (the file read), `line` (None: unknown),
    `element` (`tag[name]`), `kind` (the report's word: `not imported`, `estimated`,
    `changed`), `message` and `severity` (Policy)."""

    file: Path
    line: int | None
    element: str
    kind: str
    message: str
    severity: Severity

    @classmethod
    def at(cls, source: Located, element, kind: str, message: str, severity: Severity):
        """The record for `element` of `source`."""
        return cls(source.path, line_of(element), describe(element), kind, message, severity)

    def text(self) -> str:
        """The report line: `FILE:LINE: ELEMENT: KIND: message` (the file's name only)."""
        return f"{self.file.name}:{self.line or '?'}: {self.element}: {self.kind}: {self.message}"

    def error(self, message: str | None = None) -> SpecError:
        """The one-line refusal of this fact (`message` instead of its own, if given)."""
        return SpecError(str(self.file), self.line, self.element, message or self.message)


@dataclass(frozen=True)
class Policy:
    """Whether a fact `--strict` may refuse is a warning or an error (`strict` promotes
    every warning); facts it may not refuse (what the importer chose for a value no URDF
    carries) are notes."""

    strict: bool = False

    def severity(self, refusable: bool) -> Severity:
        if not refusable:
            return "note"
        return "error" if self.strict else "warning"


@dataclass
class Report:
    """The import's diagnostics: `records`, one per fact (a fact two steps find is kept
    once), and `refused`, the errors not yet raised, in the order found (a fact found twice
    counts twice, as the refusal's `more` says)."""

    policy: Policy = field(default_factory=Policy)
    records: list[Diagnostic] = field(default_factory=list)
    refused: list[Diagnostic] = field(default_factory=list)
    _seen: set[str] = field(default_factory=set, repr=False)

    @property
    def strict(self) -> bool:
        return self.policy.strict

    @property
    def lines(self) -> list[str]:
        """The records as report lines (`Diagnostic.text`), in order."""
        return [record.text() for record in self.records]

    def _add(self, record: Diagnostic) -> None:
        """One record per fact: an attribute read twice (by two steps) is reported once."""
        line = record.text()
        if line not in self._seen:
            self._seen.add(line)
            self.records.append(record)
        if record.severity == "error":
            self.refused.append(record)

    def dropped(self, source: Located, element, message: str) -> None:
        """An element simkit does not keep."""
        self._add(Diagnostic.at(source, element, "not imported", message, "note"))

    def estimated(self, source: Located, element, message: str) -> None:
        """A gap filled with a plausible value (refused with --strict)."""
        severity = self.policy.severity(True)
        self._add(Diagnostic.at(source, element, "estimated", message, severity))

    def assumed(self, source: Located, element, message: str) -> None:
        """An estimate of a value no URDF carries (armature): reported, not refused."""
        self._add(Diagnostic.at(source, element, "estimated", message, "note"))

    def changed(self, source: Located, element, message: str) -> None:
        """Kept, but in another form (a repaired mesh, a massless link made a frame)."""
        self._add(Diagnostic.at(source, element, "changed", message, "note"))

    def lenient(self, source: Located, element, message: str) -> None:
        """A messy form read the way the field's parsers read it: a warning (one changed
        line), or, when the policy makes it an error, refused at once."""
        record = Diagnostic.at(source, element, "changed", message, self.policy.severity(True))
        if record.severity == "error":
            raise record.error(f"{message} (--strict refuses it)")
        self._add(record)

    def raise_refused(self) -> None:
        """Raise the first error not yet raised, counting the others (`--strict`)."""
        if self.refused:
            first = self.refused[0].error()
            first.more = len(self.refused) - 1
            raise first
