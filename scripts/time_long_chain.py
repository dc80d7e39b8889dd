"""Time `simkit import` on chains of N links (issue 24: near-linear, no RecursionError).

Usage: python scripts/time_long_chain.py [N ...]   (default 500 2000 10000)
Prints N, seconds and the outcome: imported, or refused in one line (a spec holds at most
10,000 links, spec/bounds.py MAX_BODIES). Figures: docs/performance.md.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from simkit.errors import SimkitError
from simkit.importer import import_robot

LINK = (
    '<link name="l{k}"><inertial><mass value="1"/><inertia ixx="0.001" iyy="0.001" '
    'izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial><visual><geometry><box size="0.01 0.01 '
    '0.01"/></geometry></visual></link>'
)
JOINT = (
    '<joint name="j{k}" type="revolute"><parent link="l{p}"/><child link="l{k}"/>'
    '<origin xyz="0 0 0.01"/><axis xyz="1 0 0"/>'
    '<limit lower="-1" upper="1" effort="20" velocity="2"/></joint>'
)


def chain(n: int) -> str:
    """A URDF of `n` links in one chain."""
    body = [LINK.format(k=0)]
    for k in range(1, n):
        body += [LINK.format(k=k), JOINT.format(k=k, p=k - 1)]
    return '<?xml version="1.0"?>\n<robot name="chain">\n' + "\n".join(body) + "\n</robot>\n"


def main(sizes: list[int]) -> None:
    for n in sizes:
        with tempfile.TemporaryDirectory() as tmp:
            urdf = Path(tmp) / "chain.urdf"
            urdf.write_text(chain(n))
            start = time.perf_counter()
            try:
                import_robot(urdf, Path(tmp) / "out")
                outcome = "imported"
            except SimkitError as exc:
                outcome = f"refused: {str(exc).split(': ', 2)[-1]}"
            print(f"{n:6d} links  {time.perf_counter() - start:7.1f} s  {outcome}", flush=True)


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [500, 2000, 10000])
