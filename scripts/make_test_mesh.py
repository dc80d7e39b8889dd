"""Write tests/specs/meshes/bracket.stl: the small, concave, mesh-sourced test solid that makes
CoACD run in the tests (issue 3). An L bracket with a bore through its foot, 16 segments per
circle so CoACD stays fast. Run: python scripts/make_test_mesh.py
"""

from __future__ import annotations

from pathlib import Path

import manifold3d as mf

from simkit.derive.solids import to_mesh
from simkit.kitio.stl import to_stl

OUT = Path(__file__).resolve().parents[1] / "tests" / "specs" / "meshes" / "bracket.stl"


def bracket() -> mf.Manifold:
    """Foot 120 x 80 x 20 mm, wall 20 x 80 x 100 mm, 30 mm bore through the foot (m)."""
    foot = mf.Manifold.cube((0.12, 0.08, 0.02), center=True).translate((0.06, 0, 0.01))
    wall = mf.Manifold.cube((0.02, 0.08, 0.10), center=True).translate((0.01, 0, 0.07))
    bore = mf.Manifold.cylinder(0.04, 0.015, 0.015, 16, center=True).translate((0.075, 0, 0.01))
    return (foot + wall) - bore


def main() -> None:
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_bytes(to_stl(to_mesh(bracket()), "bracket"))
    print(OUT)


if __name__ == "__main__":
    main()
