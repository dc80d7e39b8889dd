"""One identity per spec (issue 38): a kit's bytes depend on the spec's contents and file
name, never on how the build names it. Each seed is built by robot name, by a path relative
to the repository, by an absolute path and by a relative path from another working directory;
the four kits (every file, the zip and the manifest) are byte-identical, and the later three
builds into the first build's `--out` are no-ops (one line, nothing written).

All five seeds: their derive, emit, simulate and check stages come from the cache after the
first build, so each seed costs one build and six cache-hit or no-op CLI runs."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import SEED_ROBOTS
from simkit.kitio import layout
from tree_snapshot import snapshot

REPO = Path(__file__).resolve().parents[1]
SRC = str(REPO / "src")
pytestmark = pytest.mark.slow  # builds every seed kit


def _build(target: str, out: Path, cwd: Path) -> str:
    """`simkit build TARGET --out OUT -q` run in `cwd`; its stdout."""
    env = {**os.environ, "PYTHONPATH": SRC}
    cmd = [sys.executable, "-m", "simkit.cli", "build", target, "--out", str(out), "-q"]
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


def _files(out: Path) -> dict[str, bytes]:
    """Every file under `out` (kit folder, zip, manifest) by relative path."""
    return {
        p.relative_to(out).as_posix(): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()
    }


@pytest.mark.parametrize("name", SEED_ROBOTS)
def test_every_way_of_naming_a_seed_gives_one_kit_and_later_builds_are_noops(name, tmp_path):
    spec = REPO / "robots" / f"{name}.yaml"
    elsewhere = tmp_path / "elsewhere" / "deeper"
    elsewhere.mkdir(parents=True)
    ways = {
        "name": (name, REPO),
        "relative": (f"robots/{name}.yaml", REPO),
        "absolute": (str(spec), tmp_path),
        "other cwd": (os.path.relpath(spec, elsewhere), elsewhere),
    }
    kits = {}
    for way, (target, cwd) in ways.items():
        out = tmp_path / way.replace(" ", "_")
        _build(target, out, cwd)
        kits[way] = _files(out)
    first = kits["name"]
    assert layout.zip_name(name) in first and f".{name}.manifest.json" in first
    for way, files in kits.items():
        assert sorted(files) == sorted(first), way
        differ = [rel for rel in first if files[rel] != first[rel]]
        assert not differ, (way, differ[:5])
    # no file names the spec's folder, only its file name
    robot_json = first[f"{layout.kit_dir_name(name)}/robot.json"].decode()
    assert f'"spec": "{name}.yaml"' in robot_json and "robots/" not in robot_json

    out = tmp_path / "name"
    before = snapshot(out)
    for way in ("relative", "absolute", "other cwd"):
        target, cwd = ways[way]
        line = _build(target, out, cwd)
        assert len(line.strip().splitlines()) == 1 and "nothing changed" in line, (way, line)
        assert snapshot(out) == before, way
