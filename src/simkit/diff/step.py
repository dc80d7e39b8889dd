"""`simkit diff` for `step/NAME.step`: a changed STEP reported as per-link volume and
bounding-box deltas (solids re-read with Open CASCADE, in the assembly frame, mm), each
against the length rule in mm (`tolerance.STEP_LENGTH_MM`) and, for volumes, that length
times the solids' area; every number shown at that tolerance. Only measured quantities are
reported: the link's shape and motion are described by its mesh rows.

Imported only when a STEP file's bytes differ, and Open CASCADE is loaded only when they
differ by more than round-off of their numbers. A file Open CASCADE cannot read is reported
as such, not raised.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

from simkit.diff.report import Change
from simkit.diff.tolerance import PARAM_SI, REL, STEP_LENGTH_MM, text_close


def step_stats(data: bytes) -> dict[str, dict] | None:
    """{link: {"volume": mm^3, "area": mm^2, "bbox": [xmin, ymin, zmin, xmax, ymax, zmax]
    mm}}, or None where Open CASCADE cannot read the file."""
    from simkit.check.readers.step import bounds, volume
    from simkit.check.step import read_step

    with tempfile.TemporaryDirectory(prefix="simkit-diff-") as tmp:
        path = Path(tmp) / "kit.step"
        path.write_bytes(data)
        try:
            with _stdout_silenced():
                parts, _text = read_step(path)
        except Exception:  # Open CASCADE raises its own error types on junk
            return None
    out = {}
    for name, solids in sorted(parts.items()):
        boxes = [bounds(s) for s in solids]
        low = [min(b[0][i] for b in boxes) for i in range(3)] if boxes else []
        high = [max(b[1][i] for b in boxes) for i in range(3)] if boxes else []
        out[name] = {
            "volume": sum(volume(s) for s in solids),
            "area": sum(_area(s) for s in solids),
            "bbox": [float(v) for v in (*low, *high)],
        }
    return out


@contextlib.contextmanager
def _stdout_silenced() -> Iterator[None]:
    """Open CASCADE's STEP parser prints syntax errors on file descriptor 1, which would
    corrupt `simkit diff --json`; they go to /dev/null while it reads."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def _area(shape) -> float:
    """Surface area of `shape` (mm^2 for STEP shapes)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(shape, props)
    return float(props.Mass())


def _solid_changes(a: dict, b: dict) -> list[tuple]:
    """(field, old, new, unit, tolerance) for one link's solids: what was measured, never a
    motion (a changed bounding box says where the solid reaches, not that it moved)."""
    out = []
    tol = STEP_LENGTH_MM * max(a["area"], b["area"])
    if abs(b["volume"] - a["volume"]) > tol + REL * abs(a["volume"]):
        out.append(("volume", a["volume"], b["volume"], "mm^3", tol))
    moved = max((abs(x - y) for x, y in zip(a["bbox"], b["bbox"], strict=True)), default=0.0)
    if len(a["bbox"]) != len(b["bbox"]) or moved > STEP_LENGTH_MM:
        out.append(("bbox", a["bbox"], b["bbox"], "mm", STEP_LENGTH_MM))
    return out


def step_changes(old: dict[str, bytes], new: dict[str, bytes]) -> list[Change]:
    """`Change`s for every STEP file whose bytes differ by more than round-off."""
    out = []
    for path in sorted(set(old) & set(new)):
        if not path.endswith(".step") or text_close(old[path], new[path], PARAM_SI):
            continue
        a, b = step_stats(old[path]), step_stats(new[path])
        if a is None or b is None:
            state = ["readable" if s is not None else "unreadable" for s in (a, b)]
            if a is None and b is None:
                state = ["unreadable", "unreadable, other bytes"]
            out.append(Change("step", path, "modified", "file", *state))
            continue
        out += [Change("step", name, "removed") for name in a if name not in b]
        out += [Change("step", name, "added") for name in b if name not in a]
        for name in (n for n in b if n in a):
            out += [Change("step", name, "modified", *c) for c in _solid_changes(a[name], b[name])]
    return out
