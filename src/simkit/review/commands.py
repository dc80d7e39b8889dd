"""The bodies of `simkit render` and `simkit diff --html`: argument parsing and progress."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from simkit.diff import Report
from simkit.review.progress import Reporter
from simkit.review.scene import Camera, parse_camera, parse_size

Say = Callable[[str], None]


def render_pngs(
    kit: Path,
    out_dir: Path,
    poses: Sequence[str],
    size: str,
    camera: str | None,
    collision: bool,
    say: Say | None,
) -> list[Path]:
    """`simkit render`: parse the options, render with a progress bar or log lines."""
    from simkit.review.render import kit_poses, render_kit

    dims = parse_size(size)
    cam = parse_camera(camera) if camera else Camera()
    with Reporter("render", say) as bar:
        bar.begin(len(set(poses)) if poses else len(kit_poses(kit)))
        return render_kit(
            kit, out_dir, list(poses) or None, dims, cam, collision, lambda p: bar.step(p.name)
        )


def diff_html(report: Report, old: Path, new: Path, out: Path, say: Say | None) -> Path:
    """`simkit diff --html`: render both kits and write the report."""
    from simkit.review.diff_html import write_report

    with Reporter("render", say) as bar:
        path = write_report(report, old, new, out, progress=bar)
    if say is not None:
        say(f"wrote {out}")
    return path
