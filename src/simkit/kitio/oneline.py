"""Text from outside (a URDF's names, its file name) made safe for one line of a spec or comment."""

from __future__ import annotations


def one_line(text: str) -> str:
    """`text` with every character that is not printable (newlines, carriage returns, YAML's
    other line breaks U+0085, U+2028, U+2029, tabs, controls) written as its escape, so a
    name can neither end a comment line nor start a YAML key of its own."""
    return "".join(
        c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text
    )
