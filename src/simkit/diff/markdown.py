"""`simkit diff` as Markdown: the full report (stdout) and the short one for a GitHub job
summary or pull request comment (`--markdown FILE`), and the cell texts the HTML report
shares. One formatting rule (issue 34): every number at the tolerance of its quantity, a
component below it 0, as in `--json` (`tolerance.quantize`). Non-finite numbers read from a
kit (NaN, inf) are printed as such, never raised.
"""

from __future__ import annotations

import json
import math

from simkit.diff.report import Change, Report
from simkit.diff.tolerance import PARAM_SI, quantize
from simkit.kitio.fmt import num

ANGLE_FIELDS = {"lower", "upper", "max_velocity", "origin_rpy", "springref", "rotation"}
#: fields that hold a bounding box (low x, y, z, high x, y, z)
BOXES = {"bbox"}
TITLES = {
    "joint": "Joints",
    "link": "Links",
    "mesh": "Meshes (link frame)",
    "collision": "Collision pieces",
    "step": "STEP solids (assembly frame, mm)",
    "usd": "USD stage (composed, per physics variant)",
    "robot_json": "Other robot.json entries",
}
#: numbers of one value listed in a cell
MAX_LISTED = 9
#: the short Markdown's table rows; the rest are counted and left to the full report
SHORT_ROWS = 40


def number(value: float) -> str:
    """`fmt.num`, with NaN and infinities written out instead of raised. Values come
    quantized (`Change`), so the digits shown are the ones the tolerance resolves."""
    x = float(value)
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return num(x)


def _is_num(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _numbers(values: list, tol: float) -> str:
    """Comma-separated numbers, each at the tolerance `tol`."""
    return ", ".join(number(quantize(float(v), tol)) for v in values)


def degrees_text(value: float, tol: float) -> str:
    """An angle kept at `tol` rad, in degrees at the power of ten just above `tol` in
    degrees (1e-6 rad -> 1e-4 deg): finer digits would show the radians' rounding."""
    shown = 10.0 ** math.ceil(math.log10(math.degrees(tol)))
    return number(quantize(math.degrees(value), shown))


def _degrees(value: float, tol: float, unit: str) -> str:
    """(D deg), an angle in radians also in degrees."""
    if not math.isfinite(math.degrees(value)):
        return ""
    return f" ({degrees_text(value, tol)} deg{unit[3:]})"


def value_text(value, unit: str, field_name: str, tol: float = PARAM_SI) -> str:
    """One old or new value with its unit (radians also in degrees)."""
    if value is None:
        return "-"
    if isinstance(value, (bool, str)):
        return str(value)
    if _is_num(value):
        text = f"{number(value)} {unit}".rstrip()
        if unit.startswith("rad") and field_name in ANGLE_FIELDS and math.isfinite(value):
            text += _degrees(value, tol, unit)
        return text
    if isinstance(value, list) and all(_is_num(v) for v in value):
        if field_name in BOXES and len(value) == 6:
            return f"({_numbers(value[:3], tol)}) to ({_numbers(value[3:], tol)}) {unit}"
        shown = [number(v) for v in value[:MAX_LISTED]]
        more = f", ... {len(value) - MAX_LISTED} more" if len(value) > MAX_LISTED else ""
        return f"({', '.join(shown)}{more}) {unit}".rstrip()
    text = json.dumps(value, sort_keys=True, default=str)
    return text if len(text) <= 80 else text[:77] + "..."


def _described(change: Change) -> str | None:
    """What a mesh's own fields say about it: moved, turned, scaled, changed shape, where."""
    a, b, tol = change.old, change.new, change.tolerance
    if change.field == "displacement" and isinstance(a, list) and isinstance(b, list):
        step = [y - x for x, y in zip(a, b, strict=True)]
        norm = math.sqrt(sum(v * v for v in step))
        return f"moved ({_numbers(step, tol)}) m, {number(quantize(norm, tol))} m"
    if change.field == "rotation" and _is_num(b):
        return f"turned {degrees_text(b, tol)} deg"
    if change.field == "scale" and _is_num(b):
        return f"scaled by {number(b)}"
    if change.field == "shape" and _is_num(b):
        return f"changed shape: surfaces up to {number(b)} m apart"
    if change.field == "region" and isinstance(b, list) and len(b) == 6:
        return f"changed within ({_numbers(b[:3], tol)}) to ({_numbers(b[3:], tol)}) m"
    if change.field in BOXES and isinstance(a, list) and isinstance(b, list) and len(a) == 6:
        step = [y - x for x, y in zip(a, b, strict=True)]
        unit = change.unit
        return f"low ({_numbers(step[:3], tol)}) {unit}, high ({_numbers(step[3:], tol)}) {unit}"
    return None


def delta_text(change: Change) -> str:
    """NEW - OLD with its unit (and in %), or what the field says about the change; every
    number at the change's tolerance."""
    a, b, tol = change.old, change.new, change.tolerance
    if change.change != "modified":
        return change.change
    said = _described(change)
    if said is not None:
        return said
    if _is_num(a) and _is_num(b):
        step = b - a
        if not math.isfinite(step):
            return "changed"
        rel = f", {num(100 * step / a, 3)} %" if a and math.isfinite(100 * step / a) else ""
        shown = number(quantize(float(step), tol)) if tol > 0 else number(step)
        return f"{'+' if step >= 0 else ''}{shown} {change.unit}".rstrip() + rel
    numeric = isinstance(a, list) and isinstance(b, list) and len(a) == len(b)
    if numeric and len(a) <= MAX_LISTED and all(_is_num(v) for v in a + b):
        steps = [y - x for x, y in zip(a, b, strict=True)]
        if all(math.isfinite(v) for v in steps):
            return f"({_numbers(steps, tol)}) {change.unit}".rstrip()
    return "changed"


def cells(change: Change) -> list[str]:
    """name, field, old, new, change: every cell filled (added and removed rows too)."""
    if change.change != "modified":
        return [change.name, "-", "-", "-", change.change]
    shown = [
        value_text(value, change.unit, change.field, change.tolerance)
        for value in (change.old, change.new)
    ]
    if change.field in ("shape", "region"):  # a measure of the change, not an old or new value
        shown = ["-", "-"]
    return [change.name, change.field or "-", *shown, delta_text(change)]


def summary(report: Report) -> str:
    more = len(report.round_off)
    round_off = f" ({more} more differ only by round-off, comments or provenance)" if more else ""
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
        "only by round-off, comments or provenance)."
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
        ("round-off, comments or provenance only", report.round_off),
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
