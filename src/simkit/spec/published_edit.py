"""Rewrite values of a spec's `published:` block in place (`simkit build --accept-published`).

Only the characters of each value that changes are replaced: every other byte of the file
(comments, key order, indentation, flow or block style, the other numbers' spelling) stays
as it was. The value's place comes from PyYAML's node marks (the parser that reads specs),
so no second YAML library re-emits the document. A round-trip dumper (ruamel.yaml) would
rewrap long lines and renormalise indentation and float spelling elsewhere in the file.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import yaml

from simkit.errors import SpecError


@dataclass(frozen=True)
class Edit:
    """One rewritten value: `field` as the spec's errors name it, its 1-based line."""

    field: str
    line: int
    old: str
    new: str


def spelled(value: float, tolerance: float) -> str:
    """`value` with two more decimals than `tolerance` resolves (0.01 kg -> 4 decimals,
    0.1 mm -> 6), trailing zeros dropped: a number a person can read that the check still
    takes (within a hundredth of its tolerance)."""
    decimals = max(0, math.ceil(-math.log10(tolerance)) + 2)
    text = f"{round(float(value), decimals):.{decimals}f}"
    if "." in text:
        text = text.rstrip("0")
        text += "0" if text.endswith(".") else ""
    return "0.0" if text in ("-0.0", "-0") else text


def _node(root: yaml.Node, key: str) -> yaml.Node | None:
    if not isinstance(root, yaml.MappingNode):
        return None
    for key_node, value_node in root.value:
        if isinstance(key_node, yaml.ScalarNode) and key_node.value == key:
            return value_node
    return None


def _scalars(node: yaml.Node, field: str) -> list[tuple[str, yaml.ScalarNode]]:
    """(field path, scalar node) of a published value: itself, or each item of a list."""
    if isinstance(node, yaml.ScalarNode):
        return [(field, node)]
    if isinstance(node, yaml.SequenceNode):
        return [(f"{field}[{i}]", item) for i, item in enumerate(node.value)]
    return []


def rewrite_published(
    text: str, file: str, values: dict[str, tuple[Any, float]]
) -> tuple[str, list[Edit]]:
    """`text` with each `published.FIELD` in `values` ({field: (model value, tolerance)})
    set to the model's value where the spec's differs by more than the tolerance (for a
    list, each entry that does). Returns the new text and the edits, in file order."""
    root = yaml.compose(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    block = _node(root, "published")
    spans: list[tuple[int, int, Edit]] = []
    for field, (model, tolerance) in sorted(values.items()):
        node = _node(block, field) if block is not None else None
        if node is None:
            continue
        targets = [model] if isinstance(node, yaml.ScalarNode) else list(model)
        scalars = _scalars(node, f"published.{field}")
        if len(scalars) != len(targets):
            line = node.start_mark.line + 1
            why = f"{len(scalars)} values here, the model gives {len(targets)}"
            raise SpecError(file, line, f"published.{field}", why)
        for (path, scalar), target in zip(scalars, targets, strict=True):
            old = text[scalar.start_mark.index : scalar.end_mark.index]
            if not math.isfinite(float(target)):  # the model gives none: nothing to accept
                continue
            try:
                same = abs(float(scalar.value) - float(target)) <= tolerance
            except ValueError:
                same = False
            if not same:
                edit = Edit(path, scalar.start_mark.line + 1, old, spelled(target, tolerance))
                spans.append((scalar.start_mark.index, scalar.end_mark.index, edit))
    out = text
    for start, end, edit in sorted(spans, key=lambda span: span[0], reverse=True):
        out = _splice(out, start, end, edit.new)
    return out, [edit for _, _, edit in sorted(spans, key=lambda span: span[0])]


def _splice(text: str, start: int, end: int, new: str) -> str:
    """`text` with [start, end) replaced by `new`; a comment after the value keeps its
    column where the spaces before it allow (one space at least)."""
    gap = len(text[end:]) - len(text[end:].lstrip(" "))
    if text[end + gap : end + gap + 1] == "#" and gap:
        width = max(1, gap + (end - start) - len(new))
        return text[:start] + new + " " * width + text[end + gap :]
    return text[:start] + new + text[end:]
