"""`simkit diff` as Markdown: the full report (stdout) and the short one for a GitHub job
summary or pull request comment (`--markdown FILE`), and the cell texts the HTML report
shares. Non-finite numbers read from a kit (NaN, inf) are printed as such, never raised.
"""

from __future__ import annotations

import json
import math

from simkit.diff.report import Change, Report
from simkit.kitio.fmt import num

ANGLE_FIELDS = {"lower", "upper", "max_velocity", "origin_rpy", "springref", "rotation"}
TITLES = {
    "joint": "Joints",
    "link": "Links",
    "mesh": "Meshes (link frame)",
    "collision": "Collision pieces",
    "step": "STEP solids (assembly frame, mm)",
    "robot_json": "Other robot.json entries",
}
#: numbers of one value listed in a cell
MAX_LISTED = 9
#: the short Markdown's table rows; the rest are counted and left to the full report
SHORT_ROWS = 40


def number(value: float, digits: int = 6) -> str:
    """`fmt.num`, with NaN and infinities written out instead of raised."""
    x = float(value)
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return num(x, digits)


def _is_num(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def value_text(value, unit: str, field_name: str) -> str:
    """One old or new value with its unit (radians also in degrees)."""
    if value is None:
        return "-"
    if isinstance(value, (bool, str)):
        return str(value)
    if _is_num(value):
        text = f"{number(value)} {unit}".rstrip()
        if unit.startswith("rad") and field_name in ANGLE_FIELDS and math.isfinite(value):
            degrees = math.degrees(value)
            text += f" ({number(degrees, 5)} deg{unit[3:]})" if math.isfinite(degrees) else ""
        return text
    if isinstance(value, list) and all(_is_num(v) for v in value):
        shown = [number(v) for v in value[:MAX_LISTED]]
        more = f", ... {len(value) - MAX_LISTED} more" if len(value) > MAX_LISTED else ""
        return f"({', '.join(shown)}{more}) {unit}".rstrip()
    text = json.dumps(value, sort_keys=True, default=str)
    return text if len(text) <= 80 else text[:77] + "..."


def delta_text(change: Change) -> str:
    """NEW - OLD with its unit (and in %), or what the field says about the change."""
    a, b = change.old, change.new
    if change.change != "modified":
        return change.change
    if change.field == "displacement" and isinstance(a, list) and isinstance(b, list):
        d = [y - x for x, y in zip(a, b, strict=True)]
        norm = math.sqrt(sum(v * v for v in d))
        return f"moved ({', '.join(number(v) for v in d)}) m, {number(norm)} m"
    if change.field == "rotation" and _is_num(b):
        return f"turned {number(math.degrees(b), 5)} deg"
    if change.field == "shape" and _is_num(b):
        return f"vertices up to {number(b)} m off a rigid motion"
    if _is_num(a) and _is_num(b):
        step = b - a
        if not math.isfinite(step):
            return "changed"
        rel = f", {number(100 * step / a, 3)} %" if a and math.isfinite(100 * step / a) else ""
        return f"{'+' if step >= 0 else ''}{number(step)} {change.unit}".rstrip() + rel
    numeric = isinstance(a, list) and isinstance(b, list) and len(a) == len(b)
    if numeric and len(a) <= MAX_LISTED and all(_is_num(v) for v in a + b):
        steps = [y - x for x, y in zip(a, b, strict=True)]
        if all(math.isfinite(v) for v in steps):
            return f"({', '.join(number(v) for v in steps)}) {change.unit}".rstrip()
    return "changed"


def cells(change: Change) -> list[str]:
    """name, field, old, new, change: every cell filled (added and removed rows too)."""
    if change.change != "modified":
        return [change.name, "-", "-", "-", change.change]
    return [
        change.name,
        change.field or "-",
        value_text(change.old, change.unit, change.field),
        value_text(change.new, change.unit, change.field),
        delta_text(change),
    ]


def summary(report: Report) -> str:
    more = len(report.round_off)
    round_off = f" ({more} more differ only by round-off)" if more else ""
    return (
        f"{len(report.changes)} change(s) beyond the checks' tolerances; files: "
        f"{len(report.added)} added, {len(report.removed)} removed, "
        f"{len(report.changed)} changed{round_off}."
    )


def no_change(report: Report) -> str:
    if report.identical:
        return "No changes: every file is byte-identical."
    return (
        f"No changes beyond the checks' tolerances ({len(report.round_off)} file(s) differ "
        "only by round-off or provenance)."
    )


def to_markdown(report: Report) -> str:
    """The report as Markdown, for a pull request comment."""
    lines = [f"# simkit diff: `{report.old}` -> `{report.new}`", ""]
    if report.equal:
        return "\n".join([*lines, no_change(report), ""])
    lines += [summary(report), ""]
    for kind, title in TITLES.items():
        items = [c for c in report.changes if c.kind == kind]
        if not items:
            continue
        lines += [f"## {title}", ""]
        lines += [f"- `{c.name}` {c.change}" for c in items if c.change != "modified"]
        modified = [c for c in items if c.change == "modified"]
        if modified:
            lines += ["| name | field | old | new | change |", "|---|---|---|---|---|"]
            lines += [_row([f"`{c.name}`", *cells(c)[1:]]) for c in modified]
        lines.append("")
    lines += ["## Files", ""]
    for label, paths in (
        ("added", report.added),
        ("removed", report.removed),
        ("changed", report.changed),
        ("round-off only", report.round_off),
    ):
        if paths:
            lines.append(f"- {label}: " + ", ".join(f"`{p}`" for p in paths))
    if report.metadata:
        lines.append("- provenance: " + ", ".join(f"`{p}`" for p in report.metadata))
    return "\n".join([*lines, ""])


def _row(values: list[str]) -> str:
    return "| " + " | ".join(v.replace("|", "\\|") for v in values) + " |"


def to_short_markdown(report: Report, full: str) -> str:
    """At most ~60 lines for a job summary: the table first, then the files in one line and
    a pointer to the full report `full` (the HTML file, or how to make it)."""
    lines = [f"### simkit diff: `{report.old}` -> `{report.new}`", ""]
    if report.equal:
        return "\n".join([*lines, no_change(report), "", full, ""])
    lines += ["| kind | name | field | old | new | change |", "|---|---|---|---|---|---|"]
    rows = [_row([TITLES[c.kind], f"`{c.name}`", *cells(c)[1:]]) for c in report.changes]
    lines += rows[:SHORT_ROWS]
    if len(rows) > SHORT_ROWS:
        lines.append(f"| ... | {len(rows) - SHORT_ROWS} more | - | - | - | see the full report |")
    lines += ["", summary(report)]
    if report.changed:
        shown = ", ".join(f"`{p}`" for p in report.changed[:6])
        lines.append(f"Changed files: {shown}{', ...' if len(report.changed) > 6 else ''}")
    return "\n".join([*lines, "", full, ""])
