"""The content-addressed cache: keys, atomic writes, corruption repair, no pickle, location."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner

from simkit.kitio.cache import ENV_DIR, Cache, default_dir, make_key


def test_key_covers_inputs_step_version_and_every_parameter():
    base = make_key("step", 1, [b"mesh"], {"a": 1.0, "b": [1, 2]}, ("numpy",))
    assert base == make_key("step", 1, [b"mesh"], {"b": [1, 2], "a": 1.0}, ("numpy",))
    variants = [
        make_key("step", 1, [b"mesh!"], {"a": 1.0, "b": [1, 2]}, ("numpy",)),
        make_key("other", 1, [b"mesh"], {"a": 1.0, "b": [1, 2]}, ("numpy",)),
        make_key("step", 2, [b"mesh"], {"a": 1.0, "b": [1, 2]}, ("numpy",)),
        make_key("step", 1, [b"mesh"], {"a": 1.0000001, "b": [1, 2]}, ("numpy",)),
        make_key("step", 1, [b"mesh"], {"a": 1.0, "b": [1, 2]}, ("numpy", "manifold3d")),
        make_key("step", 1, [b"me", b"sh"], {"a": 1.0, "b": [1, 2]}, ("numpy",)),
    ]
    assert len({base, *variants}) == len(variants) + 1


def test_roundtrip_is_atomic_and_leaves_no_temp_files(tmp_path):
    cache = Cache.at(tmp_path)
    arrays = {"v": np.arange(12.0).reshape(4, 3), "f": np.array([[0, 1, 2]], np.int64)}
    key = make_key("s", 1, [b"x"], {})
    assert cache.get("s", key) is None
    cache.put("s", key, arrays)
    files = [p for p in tmp_path.rglob("*") if p.is_file()]
    assert [p.suffix for p in files] == [".npz"]
    got = cache.get("s", key)
    assert got is not None and set(got) == {"v", "f"}
    np.testing.assert_array_equal(got["v"], arrays["v"])
    assert cache.stats.hits == {"s": 1} and cache.stats.misses == {"s": 1}


@pytest.mark.parametrize("damage", ["truncate", "flip", "garbage", "empty"])
def test_corrupt_entry_is_detected_removed_and_recomputed(tmp_path, damage):
    cache = Cache.at(tmp_path)
    key = make_key("s", 1, [b"x"], {})
    cache.put("s", key, {"v": np.linspace(0.0, 1.0, 1000)})
    path = cache.path("s", key)
    data = bytearray(path.read_bytes())
    if damage == "truncate":
        data = data[: len(data) // 2]
    elif damage == "flip":  # a silent bit flip inside the array data: only the digest sees it
        data[len(data) // 2] ^= 0x01
    elif damage == "garbage":
        data = bytearray(b"not a zip file" * 10)
    else:
        data = bytearray()
    path.write_bytes(bytes(data))
    assert cache.get("s", key) is None
    assert not path.exists()
    assert cache.stats.repaired == {"s": 1}
    calls = []
    got = cache.memo("s", key, lambda: calls.append(1) or {"v": np.linspace(0.0, 1.0, 1000)})
    assert calls == [1] and np.allclose(got["v"], np.linspace(0.0, 1.0, 1000))
    assert cache.get("s", key) is not None


def test_no_pickle(tmp_path):
    cache = Cache.at(tmp_path)
    with pytest.raises(TypeError):
        cache.put("s", "ab" * 32, {"o": np.array([{"a": 1}], dtype=object)})
    assert not list(tmp_path.rglob("*.npz"))


def test_disabled_cache_stores_nothing(tmp_path):
    cache = Cache.disabled()
    cache.put("s", "ab" * 32, {"v": np.zeros(3)})
    assert cache.get("s", "ab" * 32) is None
    assert not list(tmp_path.rglob("*"))


def test_location_env_then_user_cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv(ENV_DIR, str(tmp_path / "env"))
    assert default_dir() == tmp_path / "env"
    assert Cache.at().root == tmp_path / "env"
    assert Cache.at(tmp_path / "flag").root == tmp_path / "flag"
    monkeypatch.delenv(ENV_DIR)
    from platformdirs import user_cache_dir

    assert default_dir() == type(default_dir())(user_cache_dir("simkit", appauthor=False))


@pytest.mark.slow
def test_cli_cache_dir_and_no_cache(tmp_path):
    """`--no-cache` writes no entry; `--cache-dir` fills the folder given (link solids and
    collision pieces of every link)."""
    from simkit.cli import main

    runner = CliRunner()
    off, on = tmp_path / "off", tmp_path / "on"
    args = ["build", "rosie_1000", "--out", str(tmp_path / "kits"), "-q", "--no-check", "-j", "1"]
    result = runner.invoke(main, [*args, "--cache-dir", str(off), "--no-cache"])
    assert result.exit_code == 0, result.output
    assert not off.exists() or not list(off.rglob("*.npz"))
    result = runner.invoke(main, [*args, "--cache-dir", str(on)])
    assert result.exit_code == 0, result.output
    assert len(list((on / "collision").rglob("*.npz"))) == 7
    assert len(list((on / "link_solid").rglob("*.npz"))) == 7


@pytest.mark.slow
def test_warm_derive_hits_every_step_and_emits_the_same_bytes(tmp_path):
    """Link solids, collision pieces and the cached robot-level steps come back from the
    cache, and the kit's files are byte-identical to the cold build's."""
    from simkit.emit import emit_all
    from simkit.pipeline import model_from_spec

    cold = emit_all(model_from_spec("rosie_1000", cache=Cache.at(tmp_path), jobs=1))
    warm_cache = Cache.at(tmp_path)
    warm = emit_all(model_from_spec("rosie_1000", cache=warm_cache, jobs=1))
    assert "link_solid" not in warm_cache.stats.misses
    assert "collision" not in warm_cache.stats.misses
    assert warm_cache.stats.hits["link_solid"] == 7 and warm_cache.stats.hits["collision"] == 7
    assert any(step.startswith("derived_") for step in warm_cache.stats.hits)
    assert warm == cold
    # a warm derive and emit import neither CoACD nor trimesh (issue 3: lazy imports)
    code = (
        "import sys; from simkit.pipeline import model_from_spec; "
        "from simkit.kitio.cache import Cache; "
        "from simkit.emit import emit_all; "
        f"emit_all(model_from_spec('rosie_1000', cache=Cache.at({str(tmp_path)!r}))); "
        "print(sorted(m for m in ('coacd', 'trimesh') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
