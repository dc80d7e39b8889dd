"""`simkit diff OLD NEW --html REPORT.html`: the visual diff a CI job uploads for a pull request.

One self-contained HTML file (images are `data:` URIs; no scripts, links or fetches): the
semantic change table of `simkit diff`, then for every named pose the OLD render, the NEW
render and a difference image (NEW faded, changed pixels in magenta); a row with collision
geometry shown when collision meshes changed. OLD and NEW share one camera, so an unchanged
part of the robot is drawn on the same pixels in both.
"""

from __future__ import annotations

import base64
import html
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from simkit.diff import Change, Report
from simkit.diff.markdown import TITLES, cells, no_change, summary
from simkit.errors import SimkitError
from simkit.review.png import png_bytes, read_png
from simkit.review.progress import Reporter
from simkit.review.render import DEFAULT_SIZE, Item, kit_poses, run_job

#: changed pixels in the difference image (RGB), over NEW faded towards white by FADE
HIGHLIGHT = (230, 0, 126)
FADE = 0.7

STYLE = """
body { font: 14px/1.45 system-ui, sans-serif; margin: 2em; color: #1d1f23; }
code { background: #f1f2f4; padding: 0 3px; border-radius: 3px; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
th, td { border: 1px solid #d5d8dc; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #f6f7f8; }
table.renders td { padding: 4px; }
table.renders img { display: block; max-width: 100%; height: auto; }
.note { color: #5b6068; font-size: 12px; font-weight: normal; }
"""


@dataclass
class Row:
    """One row of images: PNG bytes of OLD, NEW and their difference (None where the pose is
    missing on one side), and the number of changed pixels."""

    title: str
    old: bytes | None
    new: bytes | None
    diff: bytes | None
    changed: int
    pixels: int


def diff_image(old: np.ndarray, new: np.ndarray) -> tuple[np.ndarray, int]:
    """NEW faded towards white with every pixel that differs from OLD in HIGHLIGHT."""
    changed = np.any(old != new, axis=2)
    faded = (new.astype(np.float64) * (1 - FADE) + 255 * FADE).astype(np.uint8)
    faded[changed] = HIGHLIGHT
    return faded, int(changed.sum())


def collision_changed(report: Report) -> bool:
    """Did the collision files change: meshes' bytes or a link's number of pieces."""
    paths = [*report.added, *report.removed, *report.changed]
    return any(p.startswith("meshes/collision/") for p in paths) or any(
        c.kind == "collision" for c in report.changes
    )


def render_rows(
    old: Path,
    new: Path,
    report: Report,
    size: tuple[int, int] = DEFAULT_SIZE,
    progress: Reporter | None = None,
) -> list[Row]:
    """Render both kits (one process, one camera) and pair the images row by row. The
    collision view of the first common pose is a row when the collision geometry differs."""
    poses_old, poses_new = kit_poses(old), kit_poses(new)
    names = list(dict.fromkeys([*poses_new, *poses_old]))
    views = [(name, False) for name in names]
    common = [n for n in names if n in poses_old and n in poses_new]
    if common:
        views.append((common[0], True))
    with tempfile.TemporaryDirectory(prefix="simkit-diff-") as tmp:
        items, files = [], {}
        for k, (name, collision) in enumerate(views):
            for side, poses in ((0, poses_old), (1, poses_new)):
                if name in poses:
                    label = f"{('old', 'new')[side]}-{name}{'-collision' if collision else ''}"
                    files[k, side] = Path(tmp) / f"{k:02d}-{label}.png"
                    items.append(Item(side, name, collision, files[k, side]))
        if progress is not None:
            progress.begin(len(items))
        step = (lambda p: progress.step(p.stem[3:])) if progress is not None else None
        result = run_job([old, new], items, size, on_image=step)
        same = result["collision"][0] == result["collision"][1]
        if common and same and not collision_changed(report):
            views.pop()
        return [
            _row(name, collision, files.get((k, 0)), files.get((k, 1)))
            for k, (name, collision) in enumerate(views)
        ]


def _row(name: str, collision: bool, old: Path | None, new: Path | None) -> Row:
    title = f"{name} (collision geometry)" if collision else name
    old_png = old.read_bytes() if old else None
    new_png = new.read_bytes() if new else None
    if old is None or new is None:
        return Row(title, old_png, new_png, None, 0, 0)
    pixels, changed = diff_image(read_png(old), read_png(new))
    return Row(
        title, old_png, new_png, png_bytes(pixels), changed, pixels.shape[0] * pixels.shape[1]
    )


def _img(data: bytes | None, alt: str) -> str:
    if data is None:
        return '<td class="note">no such pose</td>'
    uri = "data:image/png;base64," + base64.b64encode(data).decode("ascii")
    return f'<td><img alt="{html.escape(alt)}" src="{uri}"></td>'


def _changes_html(changes: Sequence[Change]) -> list[str]:
    """One table per kind of change; every cell filled (`diff.markdown.cells`)."""
    out = []
    for kind, title in TITLES.items():
        items = [c for c in changes if c.kind == kind]
        if not items:
            continue
        out.append(f"<h3>{html.escape(title)}</h3>")
        rows = ["<tr><th>name</th><th>field</th><th>old</th><th>new</th><th>change</th></tr>"]
        rows += [
            "<tr>" + "".join(f"<td>{html.escape(v)}</td>" for v in cells(c)) + "</tr>"
            for c in items
        ]
        out.append("<table>" + "".join(rows) + "</table>")
    return out


def to_html(report: Report, rows: Sequence[Row]) -> str:
    """The report and image rows as one HTML document (UTF-8 text)."""
    esc = html.escape
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>simkit diff: {esc(report.old)} -&gt; {esc(report.new)}</title>",
        f"<style>{STYLE}</style></head><body>",
        f"<h1>simkit diff</h1><p>OLD <code>{esc(report.old)}</code><br>"
        f"NEW <code>{esc(report.new)}</code></p>",
    ]
    if report.equal:
        parts.append(f"<p>{esc(no_change(report))}</p>")
    else:
        parts.append(f"<p>{esc(summary(report))}</p>")
    parts += ["<h2>Changes</h2>", *_changes_html(report.changes)]
    files = [
        (label, paths)
        for label, paths in (
            ("added", report.added),
            ("removed", report.removed),
            ("changed", report.changed),
            ("round-off, comments or provenance only", report.round_off),
            ("provenance", report.metadata),
        )
        if paths
    ]
    if files:
        parts.append("<h3>Files</h3><ul>")
        parts += [
            f"<li>{label}: " + ", ".join(f"<code>{esc(p)}</code>" for p in paths) + "</li>"
            for label, paths in files
        ]
        parts.append("</ul>")
    parts += [
        "<h2>Renders</h2>",
        '<table class="renders"><tr><th>pose</th><th>OLD</th><th>NEW</th>'
        "<th>difference (changed pixels in magenta)</th></tr>",
    ]
    for row in rows:
        share = 100.0 * row.changed / row.pixels if row.pixels else 0.0
        note = f"{row.changed} pixels changed ({share:.2f} %)" if row.diff else ""
        parts.append(
            f'<tr><th>{esc(row.title)}<br><span class="note">{note}</span></th>'
            + _img(row.old, f"OLD {row.title}")
            + _img(row.new, f"NEW {row.title}")
            + (_img(row.diff, f"difference {row.title}") if row.diff else '<td class="note">-</td>')
            + "</tr>"
        )
    parts += ["</table>", "</body></html>", ""]
    return "\n".join(parts)


def write_report(
    report: Report,
    old: Path,
    new: Path,
    out: Path,
    size: tuple[int, int] = DEFAULT_SIZE,
    progress: Reporter | None = None,
) -> Path:
    """Render, compose and write the HTML report to `out` (written only when complete; an
    output that cannot be created is one line naming it, before anything is rendered)."""
    tmp = out.with_name(out.name + ".part")
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_bytes(b"")
    except OSError as exc:
        raise SimkitError(f"{out}: cannot write the report ({_why(exc)})") from None
    try:
        text = to_html(report, render_rows(old, new, report, size, progress))
        tmp.write_text(text, encoding="utf-8")
        tmp.replace(out)
    except OSError as exc:
        raise SimkitError(f"{out}: cannot write the report ({_why(exc)})") from None
    finally:
        tmp.unlink(missing_ok=True)
    return out


def _why(exc: OSError) -> str:
    """The OS's reason, with the path it concerns: `NAME: File exists`."""
    return f"{exc.filename}: {exc.strerror}" if exc.filename and exc.strerror else str(exc)
