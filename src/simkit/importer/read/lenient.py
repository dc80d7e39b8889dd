"""Lenient reading of the messy but common URDF forms PyBullet and yourdfpy accept.

Pure byte and string helpers; source.py reports each one (one line) or, with `--strict`,
refuses it. See docs/importing.md, "Lenient reading".
"""

from __future__ import annotations

import codecs
import re
from collections.abc import Callable
from dataclasses import dataclass

DECLARATION = re.compile(rb"<\?xml\s[^>]*?\?>")
VERSION = re.compile(rb"""version\s*=\s*["']([^"']*)["']""")
ENCODING = re.compile(rb"""encoding\s*=\s*["']([^"']*)["']""")
BOM = codecs.BOM_UTF8
#: `$(command args...)` as roslaunch and xacro write it (no nested parentheses)
SUBSTITUTION = re.compile(r"\$\(\s*([A-Za-z_]+)((?:\s+[^()\s]+)*)\s*\)")


@dataclass(frozen=True)
class Position:
    """A place in the file that is no element (an XML declaration): reads like one for
    the report (tag, sourceline, get)."""

    tag: str
    sourceline: int | None

    def get(self, key: str, default=None):
        return default


def fix_declaration(data: bytes) -> tuple[bytes, list[tuple[int, str]]]:
    """`data` with a misplaced or odd XML declaration blanked out (same lines and columns),
    and (line, message) per fix: a declaration after blank lines or with a version other
    than 1.0/1.1 (`<?xml version="0.0"?>`). A non-UTF-8 encoding it names is honoured."""
    start = len(BOM) if data.startswith(BOM) else 0
    found = DECLARATION.search(data, start, start + 4096)
    if found is None or data[start : found.start()].strip(b" \t\r\n"):
        return data, []
    decl = found.group(0)
    version = VERSION.search(decl)
    text = version.group(1).decode("ascii", "replace") if version else ""
    line = data.count(b"\n", 0, found.start()) + 1
    notes = []
    if found.start() > start:
        notes.append((line, f"XML declaration on line {line}, after blank lines: ignored"))
    if text not in ("1.0", "1.1"):
        notes.append((line, f"XML declaration version '{text}': read as XML 1.0"))
    if not notes:
        return data, []
    blank = bytes(b if b in b"\r\n" else 32 for b in decl)
    fixed = data[: found.start()] + blank + data[found.end() :]
    encoding = ENCODING.search(decl)
    name = encoding.group(1).decode("ascii", "replace") if encoding else "utf-8"
    if codecs.lookup(name).name not in ("utf-8", "ascii"):
        fixed = fixed[start:].decode(name).encode("utf-8")
    return fixed, notes


def cut_trailing(data: bytes, line: int, column: int) -> bytes:
    """`data` up to the end of the root element, given where lxml saw extra content
    (1-based line and column)."""
    offset = 0
    for _ in range(line - 1):
        offset = data.index(b"\n", offset) + 1
    return data[: data.rfind(b">", 0, offset + max(column, 1)) + 1]


def substitute(text: str, resolve: Callable[[str, list[str]], str]) -> str:
    """`text` with each `$(command args)` replaced by `resolve(command, args)`."""
    return SUBSTITUTION.sub(lambda m: resolve(m.group(1), m.group(2).split()), text)


def first_numbers(text: str, count: int) -> tuple[float, ...] | None:
    """The first `count` numbers of a longer space-separated list, or None when `text` is
    not such a list (PyBullet reads `rpy="-3.14159 1.57079 0 0"` as its first three)."""
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        return None
    return values[:count] if len(values) > count else None


#: a number as C's strtod reads one, with the stray trailing dots some exporters write
LOOSE = re.compile(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\.*")


def loose_numbers(text: str) -> tuple[float, ...] | None:
    """Numbers separated by commas as well as spaces, each allowed stray trailing dots
    (`xyz="0.07, 0, -0.69"`, `lower="-1.57."`: PyBullet reads both); None otherwise."""
    tokens = [t for t in re.split(r"[,\s]+", text.strip()) if t]
    matches = [LOOSE.fullmatch(t) for t in tokens]
    if not tokens or not all(matches):
        return None
    return tuple(float(m.group(1)) for m in matches)
