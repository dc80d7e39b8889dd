"""Regression (issue 38): every build, a no-op included, removes what an interrupted build
of the kit left in `--out`. A real `simkit build` is killed (SIGKILL, the whole process group)
while its `.NAME.<id>.staging` folder exists; the next build, a no-op since the published kit
is intact, says so in one line and leaves `--out` as kit, zip and manifest again, keeping a
user's file and another kit's leftovers."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SPEC = REPO / "tests" / "specs" / "planar_2r.yaml"
pytestmark = pytest.mark.slow  # builds a real kit, twice


def _cmd(out: Path, cache: Path, *extra: str) -> list[str]:
    spec = out.parent / SPEC.name
    cli = [sys.executable, "-m", "simkit.cli", "build", str(spec), "--out", str(out)]
    return [*cli, *extra, "--cache-dir", str(cache)]


def _kill_while_staging(cmd: list[str], out: Path, env: dict) -> list[str]:
    """Run `cmd`, SIGKILL its process group once a staging folder appears: what it left."""
    proc = subprocess.Popen(
        cmd, env=env, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE
    )
    deadline = time.monotonic() + 600
    try:
        while not list(out.glob(".planar_2r.*.staging")):
            assert proc.poll() is None, "the build ended before staging was seen"
            assert time.monotonic() < deadline
            time.sleep(0.01)
        os.killpg(proc.pid, signal.SIGKILL)
    finally:
        proc.wait(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    return sorted(p.name for p in out.glob(".planar_2r.*.staging"))


def test_a_noop_rebuild_removes_the_staging_folder_a_kill_left(tmp_path):
    (tmp_path / SPEC.name).write_text(SPEC.read_text())
    out, cache = tmp_path / "out", tmp_path / "cache"
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    first = subprocess.run(_cmd(out, cache, "-q"), env=env, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    published = sorted(p.name for p in out.iterdir())
    (out / "notes.txt").write_text("mine")  # a user's file
    (out / ".other_kit.x1y2.staging").mkdir()  # another kit's: its own build removes it

    # --no-cache: the full build runs (it would be a no-op otherwise) and stages a kit
    left = _kill_while_staging(_cmd(out, cache, "--no-cache"), out, env)
    assert left, "the kill left no staging folder"

    again = subprocess.run(_cmd(out, cache, "-q"), env=env, capture_output=True, text=True)
    assert again.returncode == 0, again.stderr
    (line,) = again.stdout.strip().splitlines()
    assert "nothing changed since the last build" in line, line
    assert f"removed what an interrupted build left: {', '.join(left)}" in line, line
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [*published, "notes.txt", ".other_kit.x1y2.staging"]
    )
