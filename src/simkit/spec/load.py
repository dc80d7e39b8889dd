"""YAML loading that remembers the line of every value, so errors can name file and line."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from simkit.errors import SpecError

Loc = tuple[str | int, ...]

_CONSTRUCTOR = yaml.constructor.SafeConstructor()


@dataclass(frozen=True)
class SourceDoc:
    """Plain Python data from a YAML file plus a map from field path to 1-based line."""

    file: str
    data: Any
    lines: dict[Loc, int]
    text: str

    def line_of(self, loc: Loc) -> int | None:
        """Line of the deepest known prefix of `loc` (a missing key points at its parent)."""
        for n in range(len(loc), -1, -1):
            line = self.lines.get(tuple(loc[:n]))
            if line is not None:
                return line
        return None


def _walk(node: yaml.Node, loc: Loc, lines: dict[Loc, int]) -> Any:
    lines[loc] = node.start_mark.line + 1
    if isinstance(node, yaml.MappingNode):
        out: dict[str, Any] = {}
        for key_node, value_node in node.value:
            key = _CONSTRUCTOR.construct_object(key_node, deep=True)
            if not isinstance(key, str):
                raise SpecError(
                    "",
                    key_node.start_mark.line + 1,
                    ".".join(map(str, loc)) or "<root>",
                    f"keys must be strings, got {key!r}",
                )
            if key in out:
                raise SpecError(
                    "", key_node.start_mark.line + 1, _dotted((*loc, key)), "duplicate key"
                )
            lines[(*loc, key)] = key_node.start_mark.line + 1
            out[key] = _walk(value_node, (*loc, key), lines)
            lines[(*loc, key)] = key_node.start_mark.line + 1
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_walk(child, (*loc, i), lines) for i, child in enumerate(node.value)]
    return _CONSTRUCTOR.construct_object(node, deep=True)


def _dotted(loc: Loc) -> str:
    """`('links', 3, 'mass')` -> `links[3].mass`."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out or "<root>"


def dotted(loc: Loc) -> str:
    """Public form of the field path used in every spec error message."""
    return _dotted(loc)


def load_yaml(path: Path, display: str | None = None) -> SourceDoc:
    """Parse `path` into a `SourceDoc`; malformed YAML raises `SpecError` with its line."""
    name = display or str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecError(name, None, "<file>", "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(name, None, "<file>", f"cannot read: {exc}") from None
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        raise SpecError(name, line, "<yaml>", f"malformed YAML: {exc.problem}") from None
    if root is None:
        raise SpecError(name, 1, "<root>", "the spec is empty")
    lines: dict[Loc, int] = {}
    try:
        data = _walk(root, (), lines)
    except SpecError as exc:
        raise SpecError(name, exc.line, exc.field, exc.message) from None
    return SourceDoc(file=name, data=data, lines=lines, text=text)
