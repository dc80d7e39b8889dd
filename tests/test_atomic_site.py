"""The publish site swap (atomic.swap_folder): kill -9 at each step leaves the old site or the
new one, whole; the next publish puts back what a kill left aside and removes stale staging.
Both paths: renameat2 exchange, and the two-rename fallback for systems without it."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from simkit.kitio import atomic

SRC = str(Path(__file__).resolve().parents[1] / "src")

#: A child process that publishes a synthetic site (files named by `tag`) with the real code.
PUBLISH = """
import shutil, sys, tempfile
from pathlib import Path
from simkit.kitio import atomic
site, tag, exchange = Path(sys.argv[1]), sys.argv[2], sys.argv[3] == "1"
if not exchange:
    atomic._exchange = lambda a, b: False
with atomic.locked(site.parent):
    atomic.recover_folder(site)
    staging = Path(tempfile.mkdtemp(prefix=f".{site.name}.", suffix=".staging", dir=site.parent))
    staged = staging / "site"
    (staged / "kit").mkdir(parents=True)
    (staged / "index.json").write_text(tag)
    (staged / "kit" / f"{tag}.txt").write_text(tag * 50)
    atomic.swap_folder(staged, site)
    shutil.rmtree(staging)  # as publish's `finally` does
"""


def _publish(site: Path, tag: str, exchange: bool, kill_at: str | None = None) -> int:
    env = {**os.environ, "PYTHONPATH": SRC}
    env.pop(atomic.KILL_ENV, None)
    if kill_at:
        env[atomic.KILL_ENV] = kill_at
    cmd = [sys.executable, "-c", PUBLISH, str(site), tag, "1" if exchange else "0"]
    return subprocess.run(cmd, env=env, timeout=60).returncode


def _tag(site: Path) -> str | None:
    """The one publication the site shows (index and files agree), or None if no site."""
    if not site.exists():
        return None
    tag = (site / "index.json").read_text()
    files = sorted(p.relative_to(site).as_posix() for p in site.rglob("*") if p.is_file())
    assert files == ["index.json", f"kit/{tag}.txt"], files
    assert (site / "kit" / f"{tag}.txt").read_text() == tag * 50
    return tag


@pytest.mark.parametrize("exchange", [True, False], ids=["renameat2", "two_renames"])
@pytest.mark.parametrize("kill_at", atomic.FOLDER_STEPS)
def test_kill_at_each_step_leaves_one_whole_site(tmp_path, kill_at, exchange) -> None:
    site = tmp_path / "site"
    assert _publish(site, "old", exchange) == 0
    killed = _publish(site, "new", exchange, kill_at)
    ran_there = kill_at != "site_moved_aside" or not exchange  # that step is the fallback's
    assert killed == (-9 if ran_there else 0)
    # what a user sees right after the kill (the fallback's gap is closed on the next run)
    seen = _tag(site) if site.exists() else _tag(tmp_path / ".site.old")
    assert seen in ("old", "new")
    assert _publish(site, "next", exchange) == 0
    assert _tag(site) == "next"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["site"]  # nothing stale left


def test_first_publication_and_stale_staging(tmp_path) -> None:
    site = tmp_path / "site"
    stale = Path(tempfile.mkdtemp(prefix=".site.", suffix=".staging", dir=tmp_path))
    (stale / "junk").write_text("x")
    assert _publish(site, "first", exchange=True) == 0
    assert _tag(site) == "first"
    assert not stale.exists()
