"""Measure geometry.connected's gaps on built kits: the largest gap (m) at home between each
link's solid and its parent's, per kit (docs/maintaining.md, check/connected.py).

    python scripts/measure_connected.py build/*_description
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from simkit.check.connected import joint_gaps
from simkit.check.kit import Kit


def main(paths: list[str]) -> None:
    for path in paths:
        start = time.perf_counter()
        gaps = joint_gaps(Kit.open(Path(path)))
        worst = max(gaps, key=lambda g: g[3])
        took = time.perf_counter() - start
        print(
            f"{Path(path).name}: {len(gaps)} joints, largest gap {worst[3]:.3g} m "
            f"({worst[1]}-{worst[2]} at {worst[0]}), {took:.2f} s"
        )


if __name__ == "__main__":
    main(sys.argv[1:])
