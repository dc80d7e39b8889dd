"""Crash-consistent publishing (atomic.py): kill -9 at every step leaves the visible kit and
zip from one build, old or new; the next build cleans up; concurrent builds serialize."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from simkit.check.generated import kit_files
from simkit.kitio import atomic, layout
from simkit.kitio.archive import read_zip, zip_bytes

ROBOT = "toy"
SRC = str(Path(__file__).resolve().parents[1] / "src")

#: A child process that publishes a synthetic kit (files named by `tag`) with the real code.
PUBLISH = """
import sys
from pathlib import Path
from simkit.kitio import atomic
from simkit.kitio import layout
from simkit.kitio.archive import zip_bytes
out, robot, tag = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
files = {"robot.json": tag.encode(), f"meshes/{tag}.stl": tag.encode() * 100, "a/b.txt": b"x"}
with atomic.locked(out):
    atomic.repair(out, robot)
    staged = atomic.staging(out, robot)
    kit = staged / layout.kit_dir_name(robot)
    for rel, data in files.items():
        (kit / rel).parent.mkdir(parents=True, exist_ok=True)
        (kit / rel).write_bytes(data)
    (staged / layout.zip_name(robot)).write_bytes(zip_bytes(files, layout.kit_dir_name(robot)))
    atomic.commit(staged, out, robot)
"""


def _files(tag: str) -> dict[str, bytes]:
    return {"robot.json": tag.encode(), f"meshes/{tag}.stl": tag.encode() * 100, "a/b.txt": b"x"}


def _publish(out: Path, tag: str, kill_at: str | None = None) -> int:
    env = {**os.environ, "PYTHONPATH": SRC}
    env.pop(atomic.KILL_ENV, None)
    if kill_at:
        env[atomic.KILL_ENV] = kill_at
    cmd = [sys.executable, "-c", PUBLISH, str(out), ROBOT, tag]
    return subprocess.run(cmd, env=env, timeout=60).returncode


def _visible(out: Path) -> tuple[dict[str, bytes], dict[str, bytes]] | None:
    """(kit files, zip files) as a user sees them, or None when neither exists."""
    kit, zip_path = out / layout.kit_dir_name(ROBOT), out / layout.zip_name(ROBOT)
    if not kit.exists() and not zip_path.exists():
        return None
    assert kit.is_dir() and zip_path.is_file(), sorted(p.name for p in out.iterdir())
    files, problems = kit_files(kit)
    assert not problems
    return {rel: p.read_bytes() for rel, p in files.items()}, read_zip(zip_path.read_bytes())


def _legacy(out: Path, tag: str) -> None:
    """A plain kit folder and zip, as simkit wrote them before atomic.py."""
    out.mkdir(parents=True, exist_ok=True)
    kit = out / layout.kit_dir_name(ROBOT)
    for rel, data in _files(tag).items():
        (kit / rel).parent.mkdir(parents=True, exist_ok=True)
        (kit / rel).write_bytes(data)
    zip_data = zip_bytes(_files(tag), layout.kit_dir_name(ROBOT))
    (out / layout.zip_name(ROBOT)).write_bytes(zip_data)


LEGACY_STEPS = atomic.STEPS[2:6]
CASES = [(step, False) for step in atomic.STEPS if step not in LEGACY_STEPS]
CASES += [(step, True) for step in atomic.STEPS]


@pytest.mark.parametrize(
    "kill_at,legacy", CASES, ids=[f"{s}-{'legacy' if lg else 'generations'}" for s, lg in CASES]
)
def test_kill_at_each_step_leaves_one_build(tmp_path, kill_at, legacy):
    out = tmp_path / "out"
    if legacy:
        _legacy(out, "old")
    else:
        assert _publish(out, "old") == 0
    code = _publish(out, "new", kill_at)
    assert code == -9  # every step is reached (legacy_* ones only from a plain kit)
    kit, zipped = _visible(out)
    assert kit == zipped, "kit and zip come from different builds"
    assert kit in (_files("old"), _files("new"))
    if kill_at in ("switched", "linked", "cleaned"):
        assert kit == _files("new")
    # the next build recovers: consistent, and nothing stale is left
    assert _publish(out, "next") == 0
    kit, zipped = _visible(out)
    assert kit == zipped == _files("next")
    hidden = sorted(p.name for p in out.iterdir() if p.name.startswith("."))
    assert len(hidden) == 2 and f".{ROBOT}.current" in hidden, hidden
    assert os.readlink(out / f".{ROBOT}.current") in hidden


def test_kill_on_first_build_leaves_nothing_or_new(tmp_path):
    for kill_at in atomic.STEPS:
        out = tmp_path / kill_at
        _publish(out, "new", kill_at)
        seen = _visible(out)
        assert seen is None or seen[0] == seen[1] == _files("new"), kill_at


def test_concurrent_publishes_serialize(tmp_path):
    out = tmp_path / "out"
    codes: list[int] = []
    threads = [
        threading.Thread(target=lambda t=tag: codes.append(_publish(out, t)))
        for tag in ("a", "b", "c", "d")
    ]
    for thread in threads:
        thread.start()
        time.sleep(0.01)
    for thread in threads:
        thread.join()
    assert codes == [0, 0, 0, 0]
    kit, zipped = _visible(out)
    assert kit == zipped and kit in [_files(t) for t in "abcd"]
    assert not list(out.glob("*.staging")) and len(list(out.glob(".*.gen"))) == 1


def test_out_on_a_file_or_unwritable_folder_is_one_line(tmp_path):
    from simkit.errors import SimkitError

    a_file = tmp_path / "file"
    a_file.write_text("x")
    with pytest.raises(SimkitError, match="is a file"), atomic.locked(a_file):
        pass
    with pytest.raises(SimkitError, match="cannot create"), atomic.locked(a_file / "sub"):
        pass
    if os.getuid() != 0:  # root writes anywhere
        ro = tmp_path / "ro"
        ro.mkdir(mode=0o500)
        with pytest.raises(SimkitError, match="not writable"), atomic.locked(ro):
            pass


@pytest.mark.slow
def test_kill_a_real_build_at_each_step(tmp_path):
    """`simkit build` killed (SIGKILL, via the test hook) at each publishing step: the kit
    and zip on disk are always one build's, and the next build recovers."""
    spec = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
    variants = {}
    for tag in ("A", "B"):
        path = tmp_path / tag / "planar_2r.yaml"
        path.parent.mkdir()
        path.write_text(spec.read_text().replace("title: Planar 2R", f"title: Planar 2R {tag}"))
        variants[tag] = path
    out = tmp_path / "out"

    def build(tag: str, kill_at: str | None = None) -> int:
        env = {**os.environ, "PYTHONPATH": SRC}
        env.pop(atomic.KILL_ENV, None)
        if kill_at:
            env[atomic.KILL_ENV] = kill_at
        cmd = [sys.executable, "-m", "simkit.cli", "build", str(variants[tag]), "-q"]
        return subprocess.run([*cmd, "--out", str(out)], env=env, timeout=600).returncode

    def title() -> str:
        kit = out / "planar_2r_description"
        files, problems = kit_files(kit)
        assert not problems
        zipped = read_zip((out / "planar-2r-sim-kit.zip").read_bytes())
        assert zipped == {rel: p.read_bytes() for rel, p in files.items()}
        return json.loads(zipped["robot.json"])["title"]

    assert build("A") == 0 and title() == "Planar 2R A"
    old = "A"
    for kill_at in ("locked", "staged", "generation", "switched", "linked", "cleaned"):
        new = "B" if old == "A" else "A"
        assert build(new, kill_at) == -9, kill_at
        seen = title()
        assert seen in (f"Planar 2R {old}", f"Planar 2R {new}"), kill_at
        old = seen[-1]
    assert build("A") == 0 and title() == "Planar 2R A"
    assert not list(out.glob(".*.staging")) and len(list(out.glob(".*.gen"))) == 1
