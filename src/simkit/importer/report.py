"""What an import kept, estimated and left out: one line per element, never silent."""

from __future__ import annotations

from dataclasses import dataclass, field

from simkit.errors import SpecError
from simkit.importer.source import Source, describe, line_of


@dataclass
class Report:
    """Lines for the user (`FILE:LINE: ELEMENT: message`) and the problems `--strict` refuses."""

    strict: bool = False
    lines: list[str] = field(default_factory=list)
    problems: list[SpecError] = field(default_factory=list)
    _seen: set[str] = field(default_factory=set, repr=False)

    def _line(self, source: Source, element, kind: str, message: str) -> None:
        """One line per fact: an attribute read twice (by two steps) is reported once."""
        where = f"{source.path.name}:{line_of(element) or '?'}"
        line = f"{where}: {describe(element)}: {kind}: {message}"
        if line not in self._seen:
            self._seen.add(line)
            self.lines.append(line)

    def dropped(self, source: Source, element, message: str) -> None:
        """An element simkit does not keep."""
        self._line(source, element, "not imported", message)

    def estimated(self, source: Source, element, message: str) -> None:
        """A gap filled with a plausible value (refused with --strict)."""
        self._line(source, element, "estimated", message)
        self.problems.append(source.fail(element, message))

    def assumed(self, source: Source, element, message: str) -> None:
        """An estimate of a value no URDF carries (armature): reported, not refused."""
        self._line(source, element, "estimated", message)

    def changed(self, source: Source, element, message: str) -> None:
        """Kept, but in another form (a repaired mesh, a massless link made a frame)."""
        self._line(source, element, "changed", message)
