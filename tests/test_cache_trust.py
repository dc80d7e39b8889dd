"""A trustworthy cache (issue 13): entries bound to their key, bad entries are a repaired
miss with one warning, an unwritable cache never fails a build, and keys are stable."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from simkit.kitio.cache import Cache, digest, make_key


def _two(cache: Cache) -> tuple[str, str]:
    a, b = make_key("s", 1, [b"a"], {}), make_key("s", 1, [b"b"], {})
    cache.put("s", a, {"v": np.arange(3.0)})
    cache.put("s", b, {"v": np.arange(5.0)})
    return a, b


def test_swapped_content_is_a_repaired_miss(tmp_path, capsys):
    cache = Cache.at(tmp_path)
    a, b = _two(cache)
    pa, pb = cache.path("s", a), cache.path("s", b)
    data_a, data_b = pa.read_bytes(), pb.read_bytes()
    pa.write_bytes(data_b)
    pb.write_bytes(data_a)
    assert cache.get("s", a) is None and cache.get("s", b) is None
    assert cache.stats.repaired == {"s": 2} and not pa.exists() and not pb.exists()
    err = capsys.readouterr().err.strip().splitlines()
    assert err and all(line.startswith("simkit: warning: a 's' cache entry") for line in err)


def test_directory_or_symlink_entry_is_a_repaired_miss(tmp_path, capsys):
    cache = Cache.at(tmp_path)
    a, b = _two(cache)
    pa, pb = cache.path("s", a), cache.path("s", b)
    pa.unlink()
    pa.mkdir()
    (pa / "junk").write_text("x")
    assert cache.get("s", a) is None and not pa.exists()
    cache.put("s", a, {"v": np.arange(3.0)})  # repaired: the next get hits
    np.testing.assert_array_equal(cache.get("s", a)["v"], np.arange(3.0))
    pb.unlink()
    os.symlink(pa, pb)
    assert cache.get("s", b) is None and not pb.is_symlink()
    pa.unlink()
    pa.mkdir()
    cache.put("s", a, {"v": np.arange(3.0)})  # put over a folder repairs it too
    assert cache.get("s", a) is not None
    assert len(capsys.readouterr().err.strip().splitlines()) == 1  # one warning per step


def test_unwritable_cache_warns_and_goes_on(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    cache = Cache.at(blocker / "cache")  # cannot be created: a file is in the way
    key = make_key("s", 1, [b"a"], {})
    cache.put("s", key, {"v": np.arange(3.0)})
    cache.put("s", key, {"v": np.arange(3.0)})
    assert cache.get("s", key) is None
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not writable" in err[0]


def test_old_format_entry_is_a_silent_miss(tmp_path, capsys):
    import io

    cache = Cache.at(tmp_path)
    key = make_key("s", 1, [b"a"], {})
    path = cache.path("s", key)
    path.parent.mkdir(parents=True)
    from simkit.kitio.entry import DIGEST, content_digest

    arrays = {"v": np.arange(3.0)}
    arrays[DIGEST] = np.frombuffer(content_digest(arrays).encode(), dtype=np.uint8)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    path.write_bytes(buf.getvalue())
    assert cache.get("s", key) is None and capsys.readouterr().err == ""


def test_digest_is_the_same_for_numpy_and_python_scalars():
    """A cached step returns `float` where the computed one had `np.float64`: one key."""
    computed = {"a": [np.float64(0.1), np.int64(3), np.bool_(True)], "b": np.arange(3.0)}
    cached = {"a": [0.1, 3, True], "b": np.arange(3.0)}
    assert digest(computed) == digest(cached)
    assert digest({"a": [0.1]}) != digest({"a": [0.2]})


@pytest.mark.slow
def test_first_rebuild_after_a_cold_build_hits_every_entry(tmp_path):
    """Issue 13: the `emit` and `derived_freefall` keys used to change on the first rebuild
    (a cached step returns floats where the computed one had numpy scalars)."""
    from simkit.pipeline import build

    spec = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
    cold = Cache.at(tmp_path / "cache")
    build(str(spec), tmp_path / "out", cache=cold, jobs=1)
    assert cold.stats.misses and not cold.stats.hits
    warm = Cache.at(tmp_path / "cache")
    build(str(spec), tmp_path / "out", cache=warm, jobs=1)
    assert warm.stats.misses == {} and warm.stats.repaired == {}
    assert warm.stats.hits == cold.stats.misses
    entries = sorted(p.parent.parent.name for p in (tmp_path / "cache").rglob("*.npz"))
    assert entries == sorted(step for step, n in cold.stats.misses.items() for _ in range(n))


@pytest.mark.slow
def test_build_with_an_unusable_cache_folder_warns_once(tmp_path):
    import subprocess
    import sys

    blocker = tmp_path / "file"
    blocker.write_text("x")
    spec = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
    cmd = [sys.executable, "-m", "simkit.cli", "build", str(spec), "--out", str(tmp_path / "o")]
    proc = subprocess.run(
        [*cmd, "-q", "--cache-dir", str(blocker / "cache")],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    warnings = [line for line in proc.stderr.splitlines() if line.startswith("simkit: warning:")]
    assert len(warnings) == 1 and "not writable" in warnings[0], proc.stderr
    assert "Traceback" not in proc.stderr
