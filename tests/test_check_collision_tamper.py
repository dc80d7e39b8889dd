"""`collision.cover` and `collision.convex` (check/geometry.py) read the written collision
pieces and must fail on tampered ones: a piece shrunk so the visual mesh sticks out of it,
and a piece dented inward. Their measures skip points that are clearly fine (model/hull.py,
qhull's tetrahedra), so these cases show that what is left is still measured."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from simkit.check.geometry import check_collision
from simkit.check.kit import Kit


@pytest.fixture
def kit_copy(kit_factory, tmp_path) -> Path:
    built = kit_factory("ecn_2r")
    return Path(shutil.copytree(built.kit_dir, tmp_path / built.kit_dir.name))


def findings(kit_dir: Path) -> dict[str, tuple[bool, str]]:
    return {f.check: (f.ok, f.actual) for f in check_collision(Kit.open(kit_dir))}


def biggest_piece(kit_dir: Path) -> Path:
    pieces = sorted((kit_dir / "meshes" / "collision").glob("*.obj"))
    return max(pieces, key=lambda p: (p.stat().st_size, p.name))


def edit_vertices(path: Path, change) -> None:
    """Rewrite the OBJ's `v x y z` lines with `change(vertices) -> vertices` (m)."""
    lines = path.read_text().splitlines()
    rows = [i for i, line in enumerate(lines) if line.startswith("v ")]
    vertices = np.array([[float(x) for x in lines[i].split()[1:4]] for i in rows])
    for i, v in zip(rows, change(vertices), strict=True):
        lines[i] = "v " + " ".join(repr(float(x)) for x in v)
    path.write_text("\n".join(lines) + "\n")


def test_the_built_kit_passes(kit_copy: Path):
    found = findings(kit_copy)
    assert found["collision.cover"][0] and found["collision.convex"][0], found


def test_a_shrunk_piece_fails_cover(kit_copy: Path):
    def shrink(v: np.ndarray) -> np.ndarray:
        centre = v.mean(axis=0)
        return centre + 0.5 * (v - centre)

    edit_vertices(biggest_piece(kit_copy), shrink)
    ok, actual = findings(kit_copy)["collision.cover"]
    assert not ok
    assert float(re.findall(r"[-+0-9.eE]+", actual)[0]) > 1e-3  # m: well outside, measured


def test_a_dented_piece_fails_convex(kit_copy: Path):
    def dent(v: np.ndarray) -> np.ndarray:
        centre = v.mean(axis=0)
        far = int(np.argmax(np.linalg.norm(v - centre, axis=1)))
        v = v.copy()
        v[far] = centre + 0.3 * (v[far] - centre)
        return v

    edit_vertices(biggest_piece(kit_copy), dent)
    ok, actual = findings(kit_copy)["collision.convex"]
    assert not ok
    assert float(re.findall(r"[-+0-9.eE]+", actual)[0]) > 1e-4
