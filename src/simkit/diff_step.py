"""`simkit diff` for `step/NAME.step`: a changed STEP reported as per-link volume and
bounding-box deltas (solids re-read with Open CASCADE, in the assembly frame, mm).

Imported only when a STEP file's bytes differ, so other diffs never load OCP.
"""

from __future__ import annotations

import tempfile
from pathlib import Path


def step_stats(data: bytes) -> dict[str, dict]:
    """{link: {"volume": mm^3, "bbox": [xmin, ymin, zmin, xmax, ymax, zmax] mm}}."""
    from simkit.check.readers.step import bounds, volume
    from simkit.check.step import read_step

    with tempfile.TemporaryDirectory(prefix="simkit-diff-") as tmp:
        path = Path(tmp) / "kit.step"
        path.write_bytes(data)
        parts, _text = read_step(path)
    out = {}
    for name, solids in sorted(parts.items()):
        boxes = [bounds(s) for s in solids]
        low = [min(b[0][i] for b in boxes) for i in range(3)] if boxes else []
        high = [max(b[1][i] for b in boxes) for i in range(3)] if boxes else []
        out[name] = {
            "volume": round(sum(volume(s) for s in solids), 3),
            "bbox": [round(float(v), 4) for v in (*low, *high)],
        }
    return out


def step_changes(old: dict[str, bytes], new: dict[str, bytes], change) -> list:
    """`Change`s (the `change` class of diff.py) for every STEP file whose bytes differ."""
    out = []
    for path in sorted(set(old) & set(new)):
        if not path.endswith(".step") or old[path] == new[path]:
            continue
        a, b = step_stats(old[path]), step_stats(new[path])
        out += [change("step", name, "removed") for name in a if name not in b]
        out += [change("step", name, "added") for name in b if name not in a]
        for name in (n for n in b if n in a):
            for key, unit in (("volume", "mm^3"), ("bbox", "mm")):
                if a[name][key] != b[name][key]:
                    out.append(
                        change("step", name, "modified", key, a[name][key], b[name][key], unit)
                    )
    return out
