"""One canonical XML writer: element trees in, stable bytes out (two-space indent, LF,
attributes in insertion order, UTF-8 declaration)."""

from __future__ import annotations

import xml.etree.ElementTree as ET


def element(tag: str, attrib: dict[str, str] | None = None, **kw: str) -> ET.Element:
    """An element whose attributes keep the given order; None values are dropped."""
    merged = {**(attrib or {}), **kw}
    return ET.Element(tag, {k: v for k, v in merged.items() if v is not None})


def sub(
    parent: ET.Element, tag: str, attrib: dict[str, str] | None = None, **kw: str
) -> ET.Element:
    """Append a child element (see `element`)."""
    child = element(tag, attrib, **kw)
    parent.append(child)
    return child


def comment_text(text: str) -> str:
    """`text` made legal inside `<!-- -->`: control characters escaped, no `--` (which XML
    forbids in a comment: a spec named `my--robot.yaml`), no trailing `-`."""
    out = "".join(ch if ch.isprintable() else repr(ch)[1:-1] for ch in text)
    while "--" in out:
        out = out.replace("--", "-\u2010")
    return out + " " if out.endswith("-") else out


def to_bytes(root: ET.Element, comment: str | None = None) -> bytes:
    """Serialize deterministically; an optional leading comment says what made the file."""
    ET.indent(root, space="  ")
    body = ET.tostring(root, encoding="unicode", short_empty_elements=True)
    head = '<?xml version="1.0" encoding="utf-8"?>\n'
    if comment:
        head += f"<!-- {comment_text(comment)} -->\n"
    return (head + body + "\n").encode("utf-8")
