"""Fail fast (issue 38): an `--out` that cannot be written, and a disk without room for the
kit (the last kit's size there, or `room.FIRST_BUILD_BYTES` for a first build), are one line
naming the path and saying what to do, before any derive work (kitio/room.py)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from simkit.errors import SimkitError
from simkit.kitio import room

REPO = Path(__file__).resolve().parents[1]
SPEC = REPO / "tests" / "specs" / "planar_2r.yaml"


def _build(out: Path, cwd: Path, free: int | None = None) -> subprocess.CompletedProcess:
    """`simkit build` (progress on, no cache: every derive step would run and say so)."""
    env = {**os.environ, "PYTHONPATH": str(REPO / "src")}
    env.pop(room.FREE_ENV, None)
    if free is not None:
        env[room.FREE_ENV] = str(free)
    cmd = [sys.executable, "-m", "simkit.cli", "build", str(SPEC), "--out", str(out)]
    return subprocess.run(
        [*cmd, "--no-cache"], cwd=cwd, env=env, capture_output=True, text=True, timeout=300
    )


def _error_before_derive(proc: subprocess.CompletedProcess) -> str:
    """The one error line; the progress before it shows only the spec was read."""
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.strip().splitlines()
    progress = [line for line in lines if not line.startswith("simkit: error:")]
    assert progress == [f"[{SPEC}] spec {SPEC.name}"], lines  # no derive, emit, ... began
    (error,) = [line for line in lines if line.startswith("simkit: error:")]
    return error


def test_an_out_below_a_file_is_one_line_before_any_derive_work(tmp_path):
    """Root writes read-only folders, so the unwritable `--out` is one below a plain file."""
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    out = blocker / "out"
    error = _error_before_derive(_build(out, tmp_path))
    assert str(out) in error and "cannot create the output folder" in error, error
    assert "give --out a folder you can write to" in error, error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


def test_a_full_disk_is_one_line_before_any_derive_work_and_creates_nothing(tmp_path):
    out = tmp_path / "new" / "out"
    error = _error_before_derive(_build(out, tmp_path, free=1_000_000))
    assert str(out) in error and "not enough free disk space" in error, error
    assert "1 MB free" in error and "a first build needs about 16.8 MB (an estimate)" in error
    assert "free some space or give --out a folder on another disk" in error
    assert not (tmp_path / "new").exists()  # nothing created before the check passed


def _fake_kit(out: Path, robot: str, kit_bytes: int, zip_bytes: int) -> None:
    """A published kit's files of these sizes (the room check reads sizes only)."""
    kit = out / f"{robot}_description"
    (kit / "urdf").mkdir(parents=True)
    (kit / "urdf" / f"{robot}.urdf").write_bytes(b"u" * kit_bytes)
    (out / f"{robot.replace('_', '-')}-sim-kit.zip").write_bytes(b"z" * zip_bytes)


def test_the_room_needed_is_the_last_kits_size(tmp_path):
    out = tmp_path / "out"
    _fake_kit(out, "arm_2", 3_000_000, 1_000_000)
    assert room.last_kit_bytes(out, "arm_2") == 4_000_000
    room.check_room(out, "arm_2", free=4_000_000)  # exactly enough: no error
    with pytest.raises(SimkitError) as caught:
        room.check_room(out, "arm_2", free=3_999_999)
    text = str(caught.value)
    assert text.startswith(f"{out}: not enough free disk space") and "\n" not in text
    assert "4 MB free, the last arm_2 kit there took 4 MB (folder, zip and manifest)" in text
    # another kit's files in the same folder do not count
    assert room.last_kit_bytes(out, "arm_3") is None
    with pytest.raises(SimkitError, match=r"a first build needs about 16\.8 MB"):
        room.check_room(out, "arm_3", free=room.FIRST_BUILD_BYTES - 1)


def test_the_real_free_figure_is_the_disks(tmp_path, monkeypatch):
    monkeypatch.delenv(room.FREE_ENV, raising=False)
    real = shutil.disk_usage(tmp_path).free
    # a folder not made yet: its nearest existing parent's disk
    got = room.free_bytes(tmp_path / "not" / "yet")
    assert abs(got - real) < 64 * 1024 * 1024
    monkeypatch.setenv(room.FREE_ENV, "123")
    assert room.free_bytes(tmp_path) == 123
