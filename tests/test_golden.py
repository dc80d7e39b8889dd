"""Golden copies of emitted text files for a small spec: a reviewer sees every change to an
emitter's output as a diff of tests/golden/. Refresh with `pytest --update-golden`."""

from __future__ import annotations

from pathlib import Path

import pytest

from simkit.emit import docs, mjcf, srdf, urdf
from simkit.pipeline import model_from_spec

GOLDEN = Path(__file__).resolve().parent / "golden" / "planar_2r"
SPEC = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
EMITTERS = {"urdf": urdf.emit, "mjcf": mjcf.emit, "srdf": srdf.emit, "docs": docs.emit}


@pytest.fixture(scope="module")
def robot():
    return model_from_spec(str(SPEC))


@pytest.mark.parametrize("emitter", sorted(EMITTERS))
def test_emitted_text_matches_golden(robot, emitter, request):
    files = EMITTERS[emitter](robot)
    assert files, emitter
    for rel, data in sorted(files.items()):
        golden = GOLDEN / rel
        if request.config.getoption("--update-golden"):
            golden.parent.mkdir(parents=True, exist_ok=True)
            golden.write_bytes(data)
            continue
        assert golden.is_file(), f"no golden copy of {rel}: run pytest --update-golden"
        assert data.decode("utf-8") == golden.read_text(encoding="utf-8"), rel
