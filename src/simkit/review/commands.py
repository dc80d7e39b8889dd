"""The bodies of `simkit render` and `simkit diff --html`: argument parsing and progress."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from simkit.diff import Report
from simkit.errors import SimkitError
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
    try:
        _can_write(out_dir)
        with Reporter("render", say) as bar:
            bar.begin(len(set(poses)) if poses else len(kit_poses(kit)))
            return render_kit(
                kit, out_dir, list(poses) or None, dims, cam, collision, lambda p: bar.step(p.name)
            )
    except OSError as exc:
        why = f"{exc.filename}: {exc.strerror}" if exc.filename and exc.strerror else str(exc)
        raise SimkitError(f"{out_dir}: cannot write the images ({why})") from None


def _can_write(out_dir: Path) -> None:
    """Raise the OSError that writing into `out_dir` would meet, before anything renders:
    its parent is created (as render_kit does) and must take a file; `out_dir` itself, if it
    exists, must be a folder that takes one."""
    import tempfile

    out_dir.parent.mkdir(parents=True, exist_ok=True)
    for folder in (out_dir.parent, out_dir) if out_dir.exists() else (out_dir.parent,):
        if not folder.is_dir():
            raise NotADirectoryError(20, "Not a directory", str(folder))
        with tempfile.TemporaryFile(dir=folder):
            pass


def diff_html(report: Report, old: Path, new: Path, out: Path, say: Say | None) -> Path:
    """`simkit diff --html`: render both kits and write the report."""
    from simkit.review.diff_html import write_report

    with Reporter("render", say) as bar:
        path = write_report(report, old, new, out, progress=bar)
    if say is not None:
        say(f"wrote {out}")
    return path
