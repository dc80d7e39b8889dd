"""The few Markdown constructs of a kit README (emit's kit_README.md.j2) as escaped HTML:
headings, paragraphs, `-` lists, `|` tables, fenced code and inline `code`. Every character
of the source is escaped before any tag is added, so README text never becomes markup.
"""

from __future__ import annotations

import re
from html import escape

INLINE_CODE = re.compile(r"`([^`]+)`")


def inline(text: str) -> str:
    """Escaped text with `code` spans."""
    return INLINE_CODE.sub(r"<code>\1</code>", escape(text, quote=True))


def section(readme: str, title: str) -> str:
    """The Markdown under `## title` up to the next `## ` heading ('' if there is none)."""
    lines = readme.splitlines()
    try:
        start = lines.index(f"## {title}") + 1
    except ValueError:
        return ""
    end = next((i for i in range(start, len(lines)) if lines[i].startswith("## ")), len(lines))
    return "\n".join(lines[start:end]).strip("\n")


def _table(rows: list[str]) -> str:
    cells = [[c.strip() for c in row.strip().strip("|").split("|")] for row in rows]
    body = [r for r in cells[1:] if not all(set(c) <= set("-: ") for c in r)]
    head = "".join(f"<th>{inline(c)}</th>" for c in cells[0])
    rest = "".join("<tr>" + "".join(f"<td>{inline(c)}</td>" for c in r) + "</tr>" for r in body)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{rest}</tbody></table>"


def _block(lines: list[str]) -> str:
    if lines[0].startswith("|"):
        return _table(lines)
    if lines[0].startswith("- "):
        items: list[str] = []
        for line in lines:  # a line without `- ` continues the item above
            if line.startswith("- "):
                items.append(line[2:])
            else:
                items[-1] += " " + line.strip()
        return "<ul>" + "".join(f"<li>{inline(item)}</li>" for item in items) + "</ul>"
    if lines[0].startswith("#"):
        level = min(len(lines[0]) - len(lines[0].lstrip("#")) + 1, 6)
        return f"<h{level}>{inline(lines[0].lstrip('#').strip())}</h{level}>"
    return f"<p>{inline(' '.join(lines))}</p>"


def to_html(markdown: str) -> str:
    """HTML for `markdown` (the subset in the module docstring)."""
    out: list[str] = []
    block: list[str] = []
    code: list[str] | None = None
    language = ""
    for line in markdown.splitlines():
        if code is not None:
            if line.startswith("```"):
                cls = f' class="language-{escape(language)}"' if language else ""
                out.append(f"<pre><code{cls}>{escape(chr(10).join(code))}</code></pre>")
                code = None
            else:
                code.append(line)
        elif line.startswith("```"):
            if block:
                out.append(_block(block))
                block = []
            code, language = [], line[3:].strip()
        elif not line.strip():
            if block:
                out.append(_block(block))
                block = []
        else:
            block.append(line)
    if block:
        out.append(_block(block))
    return "\n".join(out)
