"""Crash-safe publishing (atomic.py): the kit is a plain folder and the zip a plain file in
--out. A kill -9 at every step leaves the kit and zip of one build, or a mismatch that the
manifest reports and the next build repairs; concurrent builds serialize; a build that
changes nothing writes nothing."""

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
from simkit.kitio import atomic, layout, manifest
from simkit.kitio.archive import read_zip, zip_bytes
from tree_snapshot import snapshot

ROBOT = "toy"
SRC = str(Path(__file__).resolve().parents[1] / "src")

#: A child process that publishes a synthetic kit (files named by `tag`) with the real code;
#: argv[4] == "0" takes renameat2 away (the two-rename path of systems without it).
PUBLISH = """
import sys
from pathlib import Path
from simkit.kitio import atomic, layout, manifest
from simkit.kitio.archive import zip_bytes
out, robot, tag = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
if sys.argv[4] == "0":
    atomic._exchange = lambda a, b: False
files = {"robot.json": tag.encode(), f"meshes/{tag}.stl": tag.encode() * 100, "a/b.txt": b"x"}
zip_data = zip_bytes(files, layout.kit_dir_name(robot))
with atomic.locked(out):
    said = atomic.repair(out, robot)
    if said:
        print(said, file=sys.stderr)
    with atomic.staging_area(out, robot) as staged:
        atomic.stage_kit(staged, out, robot, files)
        atomic.stage_file(staged, out, layout.zip_name(robot), zip_data)
        atomic.stage_file(staged, out, manifest.name(robot), manifest.make(robot, files, zip_data))
        print("changed" if atomic.commit(staged, out, robot) else "unchanged")
"""


def _files(tag: str) -> dict[str, bytes]:
    return {"robot.json": tag.encode(), f"meshes/{tag}.stl": tag.encode() * 100, "a/b.txt": b"x"}


def _publish(
    out: Path, tag: str, kill_at: str | None = None, exchange: bool = True
) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": SRC}
    env.pop(atomic.KILL_ENV, None)
    if kill_at:
        env[atomic.KILL_ENV] = kill_at
    cmd = [sys.executable, "-c", PUBLISH, str(out), ROBOT, tag, "1" if exchange else "0"]
    return subprocess.run(cmd, env=env, timeout=60, capture_output=True, text=True)


def _kit(out: Path) -> Path:
    return out / layout.kit_dir_name(ROBOT)


def _visible(
    out: Path, plain: bool = True
) -> tuple[dict[str, bytes] | None, dict[str, bytes] | None]:
    """(kit files, zip files) as a user sees them; None for a missing one. `plain`: both
    must be a plain folder and file (else links of the previous layout are followed)."""
    kit, zip_path = _kit(out), out / layout.zip_name(ROBOT)
    if plain:
        assert not kit.is_symlink() and not zip_path.is_symlink()
    kit, zip_path = kit.resolve(), zip_path.resolve()
    seen_kit = seen_zip = None
    if kit.exists():
        files, problems = kit_files(kit)
        assert not problems
        seen_kit = {rel: p.read_bytes() for rel, p in files.items()}
    if zip_path.exists():
        seen_zip = read_zip(zip_path.read_bytes())
    return seen_kit, seen_zip


def _legacy(out: Path, tag: str) -> None:
    """The generation layout of the previous simkit: kit and zip are links into
    `.NAME.current`, itself a link to a `.NAME.<id>.gen` folder."""
    gen = out / f".{ROBOT}.0a1b2c3d.gen"
    for rel, data in _files(tag).items():
        path = gen / layout.kit_dir_name(ROBOT) / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    zip_data = zip_bytes(_files(tag), layout.kit_dir_name(ROBOT))
    (gen / layout.zip_name(ROBOT)).write_bytes(zip_data)
    os.symlink(gen.name, out / f".{ROBOT}.current")
    for name in (layout.kit_dir_name(ROBOT), layout.zip_name(ROBOT)):
        os.symlink(f".{ROBOT}.current/{name}", out / name)


#: Steps after which the new kit is in place but the zip may still be the old one.
MISMATCH_STEPS = {"kit_aside", "kit_swapped"}
CASES = [
    (step, start, exchange)
    for start in ("plain", "legacy")
    for exchange in (True, False)
    for step in atomic.STEPS
]


@pytest.mark.parametrize(
    "kill_at,start,exchange",
    CASES,
    ids=[f"{s}-{st}-{'renameat2' if ex else 'two_renames'}" for s, st, ex in CASES],
)
def test_kill_at_each_step_leaves_one_build_or_a_reported_mismatch(
    tmp_path, kill_at, start, exchange
):
    out = tmp_path / "out"
    out.mkdir()
    if start == "legacy":
        _legacy(out, "old")
    else:
        assert _publish(out, "old", exchange=exchange).returncode == 0
    killed = _publish(out, "new", kill_at, exchange)
    reached = not (kill_at == "kit_aside" and exchange)  # that step is the fallback's
    assert killed.returncode == (-9 if reached else 0), killed.stderr
    seen = _visible(out, plain=start == "plain")
    kit_seen, zip_seen = seen
    if kit_seen is not None and kit_seen == zip_seen:
        assert kit_seen in (_files("old"), _files("new"))
    else:  # the new kit beside the old zip (or no kit: two renames): reported, not silent
        assert kill_at in MISMATCH_STEPS, (kill_at, seen)
        assert "interrupted" in manifest.mismatch(_kit(out))
    if kill_at in ("zip_moved", "manifest_moved", "journal_closed", "cleaned"):
        assert kit_seen == zip_seen == _files("new")
    # the next build finishes the publish (one line), then publishes its own kit
    done = _publish(out, "next", exchange=exchange)
    assert done.returncode == 0 and done.stdout.strip() == "changed"
    journaled = reached and atomic.STEPS.index(kill_at) >= atomic.STEPS.index("journaled")
    if journaled and kill_at not in ("journal_closed", "cleaned"):
        assert len(done.stderr.strip().splitlines()) == 1 and "killed" in done.stderr
    else:
        assert done.stderr == ""
    assert _visible(out) == (_files("next"), _files("next"))
    assert manifest.mismatch(_kit(out)) is None
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [f".{ROBOT}.manifest.json", layout.kit_dir_name(ROBOT), layout.zip_name(ROBOT)]
    )


@pytest.mark.parametrize("exchange", [True, False], ids=["renameat2", "two_renames"])
def test_kill_on_first_build_leaves_nothing_new_or_a_reported_gap(tmp_path, exchange):
    for kill_at in atomic.STEPS:
        out = tmp_path / kill_at
        _publish(out, "new", kill_at, exchange)
        kit_seen, zip_seen = _visible(out)
        if kit_seen != zip_seen:
            assert kill_at == "kit_swapped" and "interrupted" in manifest.mismatch(_kit(out))
        assert kit_seen in (None, _files("new")), kill_at
        assert _publish(out, "new", exchange=exchange).returncode == 0
        assert _visible(out) == (_files("new"), _files("new"))


_snapshot = snapshot


def test_a_build_that_changes_nothing_writes_nothing(tmp_path):
    out = tmp_path / "out"
    assert _publish(out, "same").stdout.strip() == "changed"
    before = _snapshot(out)
    time.sleep(0.01)
    assert _publish(out, "same").stdout.strip() == "unchanged"
    assert _snapshot(out) == before


def test_a_changed_build_keeps_the_unchanged_files_inode_and_mtime(tmp_path):
    out = tmp_path / "out"
    assert _publish(out, "one").returncode == 0
    before = _snapshot(out)
    time.sleep(0.01)
    assert _publish(out, "two").stdout.strip() == "changed"
    after = _snapshot(out)
    same = f"{layout.kit_dir_name(ROBOT)}/a/b.txt"
    assert after[same] == before[same]  # the same inode, so the same mtime
    folder = f"{layout.kit_dir_name(ROBOT)}/a"  # a new folder with the same entries and mtime
    assert after[folder][3] == before[folder][3]
    changed = f"{layout.kit_dir_name(ROBOT)}/robot.json"
    assert after[changed][1] == b"two" and after[changed][3] > before[changed][3]
    doc = json.loads((out / manifest.name(ROBOT)).read_bytes())
    assert doc["zip_sha256"] == manifest.sha256((out / layout.zip_name(ROBOT)).read_bytes())


def test_concurrent_publishes_serialize(tmp_path):
    out = tmp_path / "out"
    codes: list[int] = []
    threads = [
        threading.Thread(target=lambda t=tag: codes.append(_publish(out, t).returncode))
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
    assert manifest.mismatch(_kit(out)) is None
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [
        f".{ROBOT}.manifest.json"
    ]


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


def test_check_reports_a_zip_from_another_build_in_one_line_and_writes_nothing(tmp_path):
    """`simkit check KIT` compares the kit and the zip with the manifest beside them."""
    out = tmp_path / "out"
    assert _publish(out, "one").returncode == 0
    other = tmp_path / "other"
    assert _publish(other, "two").returncode == 0
    os.replace(other / layout.zip_name(ROBOT), out / layout.zip_name(ROBOT))
    before = _snapshot(out)
    proc = subprocess.run(
        [sys.executable, "-m", "simkit.cli", "check", str(_kit(out))],
        env={**os.environ, "PYTHONPATH": SRC},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode != 0 and proc.stdout == ""
    (line,) = proc.stderr.strip().splitlines()
    assert "different builds" in line and "the zip" in line and "Traceback" not in line
    assert _snapshot(out) == before
    # the kit from another build instead: named as the kit
    assert _publish(out, "one").returncode == 0  # repairs: the zip is republished
    assert manifest.mismatch(_kit(out)) is None
    (_kit(out) / "robot.json").write_bytes(b"tampered")
    assert "the kit does not match" in manifest.mismatch(_kit(out))


@pytest.mark.slow
def test_kill_a_real_build_at_each_step(tmp_path):
    """`simkit build` killed (SIGKILL, via the test hook) at each publishing step: the kit
    and zip on disk are one build's or reported as a mismatch, and the next build repairs."""
    spec = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
    variants = {}
    for tag in ("A", "B"):
        path = tmp_path / tag / "planar_2r.yaml"
        path.parent.mkdir()
        path.write_text(spec.read_text().replace("title: Planar 2R", f"title: Planar 2R {tag}"))
        variants[tag] = path
    out = tmp_path / "out"
    kit = out / "planar_2r_description"

    def build(tag: str, kill_at: str | None = None) -> int:
        env = {**os.environ, "PYTHONPATH": SRC}
        env.pop(atomic.KILL_ENV, None)
        if kill_at:
            env[atomic.KILL_ENV] = kill_at
        cmd = [sys.executable, "-m", "simkit.cli", "build", str(variants[tag]), "-q"]
        return subprocess.run([*cmd, "--out", str(out)], env=env, timeout=600).returncode

    def title() -> str:
        files, problems = kit_files(kit)
        assert not problems and not kit.is_symlink()
        zipped = read_zip((out / "planar-2r-sim-kit.zip").read_bytes())
        assert zipped == {rel: p.read_bytes() for rel, p in files.items()}
        return json.loads(zipped["robot.json"])["title"]

    assert build("A") == 0 and title() == "Planar 2R A"
    old = "A"
    for kill_at in ("locked", "journaled", "kit_swapped", "zip_moved", "cleaned"):
        new = "B" if old == "A" else "A"
        assert build(new, kill_at) == -9, kill_at
        if kill_at == "kit_swapped":  # the new kit beside the old zip: reported
            assert "interrupted" in manifest.mismatch(kit)
            assert build(new) == 0
        seen = title()
        assert seen in (f"Planar 2R {old}", f"Planar 2R {new}"), kill_at
        old = seen[-1]
    assert build("A") == 0 and title() == "Planar 2R A"
    assert sorted(p.name for p in out.iterdir()) == sorted(
        [".planar_2r.manifest.json", "planar-2r-sim-kit.zip", "planar_2r_description"]
    )
