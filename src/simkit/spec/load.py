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


#: Guards against hostile YAML: nesting depth, values after alias expansion, file size.
MAX_DEPTH = 48
#: values and bytes: room for a spec of `bounds.MAX_BODIES` links (an imported chain of
#: 10,000 links writes about 710,000 values in 6.6 MB, its report comments included)
MAX_NODES = 1_000_000
MAX_BYTES = 16_000_000
#: a longer integer overflows float() (the bounds check would raise); shorter ones get the
#: bounds' own message ("at most ...")
MAX_INT_DIGITS = 308
_TAGS = {
    f"tag:yaml.org,2002:{name}"
    for name in ("str", "int", "float", "bool", "null", "map", "seq", "timestamp")
}
_MERGE = "tag:yaml.org,2002:merge"


def _refuse(node: yaml.Node, loc: Loc, message: str) -> SpecError:
    return SpecError("", node.start_mark.line + 1, _dotted(loc), message)


def _walk(
    node: yaml.Node, loc: Loc, lines: dict[Loc, int], stack: tuple[int, ...] = (), count=None
) -> Any:
    count = count if count is not None else [0]
    count[0] += 1
    if count[0] > MAX_NODES:
        raise _refuse(node, loc, f"more than {MAX_NODES} values (after expanding aliases)")
    if id(node) in stack:
        raise _refuse(node, loc, "a recursive alias (a value that contains itself)")
    if len(stack) >= MAX_DEPTH:
        raise _refuse(node, loc, f"nested more than {MAX_DEPTH} levels deep")
    if node.tag not in _TAGS:
        what = "YAML merge keys (<<) are" if node.tag == _MERGE else f"the YAML tag {node.tag!r} is"
        raise _refuse(node, loc, f"{what} not supported; write the values out")
    lines[loc] = node.start_mark.line + 1
    stack = (*stack, id(node))
    if isinstance(node, yaml.MappingNode):
        out: dict[str, Any] = {}
        for key_node, value_node in node.value:
            if key_node.tag == _MERGE:
                raise _refuse(key_node, loc, "YAML merge keys (<<) are not supported")
            if not isinstance(key_node, yaml.ScalarNode) or key_node.tag not in _TAGS:
                raise _refuse(key_node, loc, "keys must be plain strings")
            key = _CONSTRUCTOR.construct_object(key_node, deep=True)
            if not isinstance(key, str):
                raise SpecError(
                    "",
                    key_node.start_mark.line + 1,
                    ".".join(map(str, loc)) or "<root>",
                    f"keys must be strings, got {key!r}",
                )
            if not key.isprintable():
                raise _refuse(key_node, loc, f"key {key!r} is not one line of printable text")
            if key in out:
                raise SpecError(
                    "", key_node.start_mark.line + 1, _dotted((*loc, key)), "duplicate key"
                )
            lines[(*loc, key)] = key_node.start_mark.line + 1
            out[key] = _walk(value_node, (*loc, key), lines, stack, count)
            lines[(*loc, key)] = key_node.start_mark.line + 1
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_walk(child, (*loc, i), lines, stack, count) for i, child in enumerate(node.value)]
    digits = sum(c.isdigit() for c in str(node.value)) if node.tag.endswith(":int") else 0
    if digits > MAX_INT_DIGITS:
        why = f"an integer of {digits} digits (at most {MAX_INT_DIGITS}) is beyond any number"
        raise _refuse(node, loc, why)
    try:
        return _CONSTRUCTOR.construct_object(node, deep=True)
    except (yaml.YAMLError, ValueError, OverflowError) as exc:
        raise _refuse(node, loc, f"not a valid value: {' '.join(str(exc).split())[:120]}") from None


def _dotted(loc: Loc) -> str:
    """`('links', 3, 'mass')` -> `links[3].mass`."""
    out = ""
    for part in loc:
        text = part if isinstance(part, int) or part.isprintable() else repr(part)
        out += f"[{text}]" if isinstance(part, int) else (f".{text}" if out else str(text))
    return out or "<root>"


def dotted(loc: Loc) -> str:
    """Public form of the field path used in every spec error message."""
    return _dotted(loc)


def _plain_text(name: str, text: str) -> None:
    """Refuse what YAML would reject without a line (NUL and other control bytes) or what
    would take long to parse (a huge file)."""
    if len(text) > MAX_BYTES:
        raise SpecError(name, None, "<file>", f"larger than {MAX_BYTES} characters")
    for n, line in enumerate(text.split("\n"), start=1):
        bad = next((c for c in line if not (c.isprintable() or c in "\t\r")), None)
        if bad is not None:
            raise SpecError(name, n, "<yaml>", f"control character {bad!r} is not allowed")


#: libyaml's parser where PyYAML has it (a humanoid's 2,800-line imported spec: 0.61 s ->
#: 0.06 s of a 2 s warm rebuild); the same nodes, marks and errors as the pure-Python one
#: otherwise
_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def load_yaml(path: Path, display: str | None = None) -> SourceDoc:
    """Parse `path` into a `SourceDoc`; malformed YAML raises `SpecError` with its line."""
    name = display or str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecError(name, None, "<file>", "no such file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError(name, None, "<file>", f"cannot read: {exc}") from None
    _plain_text(name, text)
    try:
        root = yaml.compose(text, Loader=_LOADER)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        raise SpecError(name, line, "<yaml>", f"malformed YAML: {exc.problem}") from None
    except yaml.YAMLError as exc:
        raise SpecError(
            name, None, "<yaml>", f"malformed YAML: {' '.join(str(exc).split())}"
        ) from None
    except RecursionError:
        raise SpecError(name, None, "<yaml>", f"nested more than {MAX_DEPTH} levels deep") from None
    if root is None:
        raise SpecError(name, 1, "<root>", "the spec is empty")
    lines: dict[Loc, int] = {}
    try:
        data = _walk(root, (), lines)
    except RecursionError:
        raise SpecError(name, None, "<yaml>", f"nested more than {MAX_DEPTH} levels deep") from None
    except SpecError as exc:
        raise SpecError(name, exc.line, exc.field, exc.message) from None
    return SourceDoc(file=name, data=data, lines=lines, text=text)
