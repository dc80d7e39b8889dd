"""Error types. The CLI turns every `SimkitError` into one line and a non-zero exit."""

from __future__ import annotations


class SimkitError(Exception):
    """Base class for errors that are the user's to fix (reported without a traceback)."""

    exit_code = 2


class SpecError(SimkitError):
    """A spec problem, located by file, line and dotted field path. `others`: further
    problems of the same file, (line, field, message) each, listed one per line after the
    first; `more`: how many problems are not listed."""

    def __init__(
        self,
        file: str,
        line: int | None,
        field: str,
        message: str,
        more: int = 0,
        others: tuple[tuple[int | None, str, str], ...] = (),
    ):
        self.file = file
        self.line = line
        self.field = field
        self.message = message
        self.more = more
        self.others = tuple(others)
        super().__init__(str(self))

    def __reduce__(self):  # picklable across worker processes (its __init__ takes 6 args)
        args = (self.file, self.line, self.field, self.message, self.more, self.others)
        return (type(self), args)

    def _line(self, line: int | None, field: str, message: str) -> str:
        where = f"{self.file}:{line}" if line is not None else self.file
        return f"{where}: {field}: {message}"

    def __str__(self) -> str:
        head = self._line(self.line, self.field, self.message)
        count = f"{self.more} more error{'s' if self.more != 1 else ''}"
        if not self.others:
            return head + (f" (and {count})" if self.more else "")
        lines = [head, *(self._line(*other) for other in self.others)]
        return "\n".join(lines + ([f"(and {count} not shown)"] if self.more else []))


class CheckFailed(SimkitError):
    """One or more consistency checks on a written kit failed."""

    exit_code = 3


class UnknownRobot(SimkitError):
    """A robot name that is neither a packaged spec nor an existing YAML file."""
