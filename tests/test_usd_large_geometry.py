"""A robot whose geometry text would pass the kit's per-file cap (a humanoid with dense hand
meshes: 68 MiB of `.usda` text) gets `geometries.usd` as a binary crate instead of a failed
build: `.usd` reads both encodings, the layers that reference it are unchanged, and the crate
bytes are the same on every emission (the kit stays byte-identical)."""

from __future__ import annotations

import pytest

from simkit.emit import usd
from simkit.pipeline import model_from_spec

GEOMETRY = "usd/ecn_2r/payloads/geometries.usd"


@pytest.fixture(scope="module")
def robot():
    return model_from_spec("ecn_2r")


def test_small_geometry_stays_text(robot):
    assert usd.emit(robot)[GEOMETRY].startswith(b"#usda 1.0")


def test_geometry_over_the_text_limit_is_a_crate(robot, monkeypatch, tmp_path):
    from pxr import Usd, UsdGeom

    text = usd.emit(robot)
    monkeypatch.setattr(usd, "TEXT_GEOMETRY_MAX", len(text[GEOMETRY]) - 1)
    files = usd.emit(robot)
    assert files[GEOMETRY].startswith(b"PXR-USDC") and len(files[GEOMETRY]) < len(text[GEOMETRY])
    assert files == usd.emit(robot)  # deterministic crate bytes
    assert {k for k, v in files.items() if v != text[k]} == {GEOMETRY}
    for rel, data in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_bytes(data)
    stage = Usd.Stage.Open(str(tmp_path / "usd/ecn_2r.usda"))
    meshes = [p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)]
    assert len(meshes) >= 3 and all(UsdGeom.Mesh(m).GetPointsAttr().Get() for m in meshes)


def test_the_limit_keeps_half_the_per_file_cap():
    from simkit.kitio.kitread import MAX_ENTRY

    assert usd.TEXT_GEOMETRY_MAX * 2 == MAX_ENTRY
