"""Writes outside --out (issue 24): a build writes nothing but simkit's documented cache
(matplotlib wrote ~/.cache/matplotlib and ~/.config/matplotlib), and leaves no temporary
file behind."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest


@pytest.mark.slow
@pytest.mark.parametrize("flags", [[], ["--no-cache"]], ids=["cache", "no_cache"])
def test_a_build_writes_nothing_under_home_but_the_cache(tmp_path, flags):
    home, cache, tmp, out = (tmp_path / n for n in ("home", "cache", "tmp", "out"))
    home.mkdir()
    tmp.mkdir()
    env = {k: v for k, v in os.environ.items() if not k.startswith(("XDG_", "MPL"))}
    env.update(HOME=str(home), SIMKIT_CACHE_DIR=str(cache), TMPDIR=str(tmp))
    result = subprocess.run(
        [sys.executable, "-m", "simkit.cli", "build", "ecn_2r", "--out", str(out), "-q", *flags],
        capture_output=True,
        text=True,
        env=env,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr
    assert (out / "ecn_2r_description" / "validation" / "freefall.png").is_file()
    assert sorted(p.relative_to(home).as_posix() for p in home.rglob("*")) == []
    assert sorted(p.name for p in tmp.iterdir()) == []
    if flags:  # no cache: nothing at all outside --out
        assert not cache.exists()
    else:  # matplotlib's font list lives in simkit's cache
        assert (cache / "matplotlib").is_dir()
