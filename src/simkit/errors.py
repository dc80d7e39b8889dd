"""Error types. The CLI turns every `SimkitError` into one line and a non-zero exit."""

from __future__ import annotations


class SimkitError(Exception):
    """Base class for errors that are the user's to fix (reported without a traceback)."""

    exit_code = 2


class SpecError(SimkitError):
    """A spec problem, located by file, line and dotted field path."""

    def __init__(self, file: str, line: int | None, field: str, message: str, more: int = 0):
        self.file = file
        self.line = line
        self.field = field
        self.message = message
        self.more = more
        super().__init__(str(self))

    def __reduce__(self):  # picklable across worker processes (its __init__ takes 5 args)
        return (type(self), (self.file, self.line, self.field, self.message, self.more))

    def __str__(self) -> str:
        where = f"{self.file}:{self.line}" if self.line is not None else self.file
        tail = f" (and {self.more} more error{'s' if self.more != 1 else ''})" if self.more else ""
        return f"{where}: {self.field}: {self.message}{tail}"


class CheckFailed(SimkitError):
    """One or more consistency checks on a written kit failed."""

    exit_code = 3


class UnknownRobot(SimkitError):
    """A robot name that is neither a packaged spec nor an existing YAML file."""
