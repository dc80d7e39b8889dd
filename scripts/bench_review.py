"""Time `simkit render` and `simkit diff --html` (issue 16) on built kits, as a user runs them.

Each run is its own `simkit` process (interpreter start-up, imports, the render process and
its OpenGL context all count); the median of `--runs` is reported with the image count, the
OpenGL backend used and the report's size.

    python scripts/bench_review.py build/rosie_1000_description build/asimov_description
    python scripts/bench_review.py KIT --runs 5 --size 1280x960 --json out.json
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _time(args: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "simkit.cli", *args], check=False, capture_output=True)
    return time.perf_counter() - start


def bench(kit: Path, runs: int, size: str) -> dict:
    from simkit.review.render import gl_backend, kit_poses

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        render = [
            _time(["render", str(kit), "--out", str(out / "r"), "--size", size, "-q"])
            for _ in range(runs)
        ]
        collision = [
            _time(["render", str(kit), "--out", str(out / "c"), "--size", size, "--collision"])
            for _ in range(runs)
        ]
        report = out / "report.html"
        diff = [_time(["diff", str(kit), str(kit), "--html", str(report)]) for _ in range(runs)]
        return {
            "kit": kit.name,
            "poses": len(kit_poses(kit)),
            "gl": gl_backend(),
            "size": size,
            "render_s": round(statistics.median(render), 2),
            "render_collision_s": round(statistics.median(collision), 2),
            "diff_html_s": round(statistics.median(diff), 2),
            "report_kib": round(report.stat().st_size / 1024),
        }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("kits", nargs="+", type=Path, help="built kit folders or zips")
    parser.add_argument("--runs", type=int, default=3, help="runs per command (median)")
    parser.add_argument("--size", default="640x480", help="image size WxH")
    parser.add_argument("--json", type=Path, default=None, help="also write the rows here")
    args = parser.parse_args()
    rows = [bench(kit, max(1, args.runs), args.size) for kit in args.kits]
    for row in rows:
        print("  ".join(f"{k}={v}" for k, v in row.items()))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
