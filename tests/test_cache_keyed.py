"""Cache trust (issue 24): stored paths confined to their folder, entries authenticated by
`$SIMKIT_CACHE_KEY`, a read-only mode, and a full disk that leaves nothing truncated."""

from __future__ import annotations

import io
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from simkit.kitio import confine, reuse
from simkit.kitio.cache import Cache, cached_stage, make_key
from simkit.kitio.entry import DIGEST, KEY, TAG, content_digest

SPEC = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"


def forge(path: Path, edit, keep_tag: bool = False) -> None:
    """What anyone with write access can do: edit an entry's arrays and recompute its plain
    digest (the tag needs the secret: dropped, or kept as it was)."""
    drop = (DIGEST,) if keep_tag else (DIGEST, TAG)
    with np.load(path, allow_pickle=False) as npz:
        arrays = {name: npz[name] for name in npz.files if name not in drop}
    tag = arrays.pop(TAG, None)
    edit(arrays)
    arrays[DIGEST] = np.frombuffer(content_digest(arrays).encode(), dtype=np.uint8)
    if tag is not None:
        arrays[TAG] = tag
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    path.write_bytes(buf.getvalue())


@pytest.mark.parametrize(
    "rel", ["../x", "a/../../x", "/etc/x", "a//b", "./a", "a\\..\\b", "C:x", "", "a/."]
)
def test_unsafe_stored_paths_are_refused(rel):
    with pytest.raises(confine.UnsafePath):
        confine.check_relative(rel)


def test_write_tree_never_leaves_its_root(tmp_path):
    root = tmp_path / "kit"
    with pytest.raises(confine.UnsafePath):
        reuse.write_tree(root, {"ok.txt": b"1", "../escape.txt": b"2"})
    assert not (tmp_path / "escape.txt").exists() and not (root / "ok.txt").exists()
    root.mkdir()
    (root / "link").symlink_to(tmp_path)  # a link inside the root pointing out of it
    with pytest.raises(confine.UnsafePath, match="symbolic link"):
        reuse.write_tree(root, {"link/escape.txt": b"2"})
    with pytest.raises(confine.UnsafePath, match="both a file and a folder"):
        reuse.write_tree(root, {"a": b"1", "a/b": b"2"})
    assert not (tmp_path / "escape.txt").exists()
    reuse.write_tree(root, {"sub/ok.txt": b"1"})
    assert (root / "sub" / "ok.txt").read_bytes() == b"1"


def _files_stage(cache: Cache, files: dict[str, bytes]) -> dict[str, bytes]:
    """A cached stage returning files, decoded the way the pipeline's emit stage is."""

    def decode(arrays):
        out = {k: arrays[f"f{i}"].tobytes() for i, k in enumerate(arrays["names"].tolist())}
        confine.check_tree(out)
        return out

    def encode(value):
        arrays = {f"f{i}": np.frombuffer(v, dtype=np.uint8) for i, v in enumerate(value.values())}
        return {"names": np.array(list(value)), **arrays}

    return cached_stage(cache, "files", [b"in"], lambda: files, encode, decode)


def test_a_forged_entry_with_a_climbing_path_is_a_repaired_miss(tmp_path, capsys):
    cache = Cache.at(tmp_path / "c", readonly=False, remote="")
    good = {"a.txt": b"good"}
    assert _files_stage(cache, good) == good
    (entry,) = (tmp_path / "c" / "files").rglob("*.npz")
    forge(entry, lambda a: a.update(names=np.array(["../../escape.txt"])))
    again = Cache.at(tmp_path / "c", readonly=False, remote="")
    assert _files_stage(again, good) == good  # recomputed, not the forged path
    assert again.stats.misses == {"files": 1} and again.stats.repaired == {"files": 1}
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'files' cache entry" in err[0], err
    third = Cache.at(tmp_path / "c", readonly=False, remote="")
    assert _files_stage(third, good) == good and third.stats.hits == {"files": 1}


def test_keyed_entries_refuse_forgery_and_replay(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("SIMKIT_CACHE_KEY", "s3cret")
    writer = Cache.at(tmp_path, readonly=False, remote="")
    a, b = make_key("s", 1, [b"a"], {}), make_key("s", 1, [b"b"], {})
    writer.put("s", a, {"v": np.arange(3.0)})
    np.testing.assert_array_equal(writer.get("s", a)["v"], np.arange(3.0))
    # replay: a's valid entry rebound to key b with a recomputed digest
    pb = writer.path("s", b)
    pb.parent.mkdir(parents=True, exist_ok=True)
    pb.write_bytes(writer.path("s", a).read_bytes())
    rebind = {KEY: np.frombuffer(b.encode(), dtype=np.uint8)}
    forge(pb, lambda arr: arr.update(rebind), keep_tag=True)  # a's valid tag kept
    forge(writer.path("s", a), lambda arr: arr.update(v=arr["v"] * 1.5))  # forgery
    assert writer.get("s", a) is None and writer.get("s", b) is None
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "SIMKIT_CACHE_KEY" in err[0], err
    monkeypatch.delenv("SIMKIT_CACHE_KEY")
    trusting = Cache.at(tmp_path, readonly=False, remote="")  # no key: writers are trusted
    np.testing.assert_array_equal(trusting.get("s", a)["v"], np.arange(3.0) * 1.5)
    # a keyed writer replaces an untagged entry with a tagged one
    monkeypatch.setenv("SIMKIT_CACHE_KEY", "s3cret")
    keyed = Cache.at(tmp_path, readonly=False, remote="")
    assert keyed.get("s", b) is None
    keyed.put("s", b, {"v": np.arange(5.0)})
    assert keyed.get("s", b) is not None and keyed.stats.hits == {"s": 1}


def test_readonly_cache_reads_and_never_writes(tmp_path, monkeypatch):
    key = make_key("s", 1, [b"a"], {})
    Cache.at(tmp_path / "c", readonly=False, remote="").put("s", key, {"v": np.arange(3.0)})
    before = sorted((tmp_path / "c").rglob("*"))
    monkeypatch.setenv("SIMKIT_CACHE_READONLY", "1")
    ro = Cache.at(tmp_path / "c", remote="")
    assert ro.readonly and ro.get("s", key) is not None
    other = make_key("s", 1, [b"b"], {})
    ro.put("s", other, {"v": np.arange(5.0)})
    bad = ro.path("s", key)
    bad.write_bytes(b"junk")
    assert ro.get("s", key) is None and bad.read_bytes() == b"junk"  # a miss, not removed
    assert sorted((tmp_path / "c").rglob("*")) == before
    empty = Cache.at(tmp_path / "fresh", remote="")
    empty.put("s", key, {"v": np.arange(3.0)})
    assert not (tmp_path / "fresh").exists()


def test_a_full_disk_leaves_no_truncated_entry(tmp_path):
    """RLIMIT_FSIZE makes the write fail part-way, as a full disk does: one warning naming
    the folder, no temp file, and the next read is a clean miss."""
    script = (
        "import resource, signal, sys, numpy as np\n"
        "from simkit.kitio.cache import Cache, make_key\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (65536, 65536))\n"
        f"c = Cache.at({str(tmp_path / 'c')!r}, readonly=False, remote='')\n"
        "k = make_key('s', 1, [b'a'], {})\n"
        "c.put('s', k, {'v': np.zeros(100000)})\n"
        "c.put('s', k, {'v': np.zeros(100000)})\n"
        "assert c.get('s', k) is None\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and str(tmp_path / "c") in lines[0] and "not writable" in lines[0]
    assert [p for p in (tmp_path / "c").rglob("*") if p.is_file()] == []


@pytest.mark.parametrize("command", ["build", "publish"])
def test_cache_dir_given_a_url_is_one_line_pointing_to_remote_cache(tmp_path, command):
    target = [str(SPEC)] if command == "build" else []
    cmd = [sys.executable, "-m", "simkit.cli", command, *target, "--out", str(tmp_path / "o")]
    proc = subprocess.run(
        [*cmd, "--cache-dir", "s3://bucket/prefix"], capture_output=True, text=True, cwd=tmp_path
    )
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "--remote-cache" in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # no folder named 's3:'


def test_a_full_disk_while_staging_files_is_one_line_naming_the_file(tmp_path):
    script = (
        "import resource, signal, sys\n"
        "from pathlib import Path\n"
        "from simkit.errors import SimkitError\n"
        "from simkit.kitio.reuse import write_tree\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (65536, 65536))\n"
        "try:\n"
        f"    write_tree(Path({str(tmp_path / 'kit')!r}), {{'a/big.bin': bytes(100000)}})\n"
        "except SimkitError as exc:\n"
        "    print(exc)\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    assert (
        proc.stdout.strip() == f"{tmp_path / 'kit' / 'a' / 'big.bin'}: cannot write: File too large"
    )


def _scale_solids(cache_dir: Path) -> None:
    """Issue 24's attack: every link solid and collision piece 1.5 times larger, digests
    recomputed; the robot-level entries removed so the rebuild derives from the forgery."""
    for path in sorted(cache_dir.rglob("*.npz")):
        step = path.parent.parent.name
        if step in ("link_solid", "collision", "hull"):
            forge(path, lambda a: a.update(vertices=a["vertices"] * 1.5))
        else:
            path.unlink()


def _kit_zip(out: Path) -> bytes:
    (zip_path,) = out.glob("*.zip")
    return zip_path.read_bytes()


@pytest.mark.slow
def test_scaled_solids_with_recomputed_digests_are_refused_with_a_key(tmp_path, monkeypatch):
    """Without STEP (whose solids come from the primitives, not the cache), every format
    derives from the forged solid, so every check passes on a kit 1.5 times too large."""
    from simkit.pipeline import build

    monkeypatch.setenv("SIMKIT_CACHE_KEY", "trusted-writers-only")
    cache_dir = tmp_path / "cache"
    build(str(SPEC), tmp_path / "cold", cache=Cache.at(cache_dir, remote=""), jobs=1, step=False)
    cold = _kit_zip(tmp_path / "cold")

    _scale_solids(cache_dir)
    keyed = Cache.at(cache_dir, remote="")
    result = build(str(SPEC), tmp_path / "keyed", cache=keyed, jobs=1, step=False)
    assert _kit_zip(tmp_path / "keyed") == cold and all(f.ok for f in result.findings)
    assert keyed.stats.hits == {} and keyed.stats.misses.get("link_solid")

    _scale_solids(cache_dir)  # without the key, a forgery is trusted: today's behaviour
    monkeypatch.delenv("SIMKIT_CACHE_KEY")
    trusting = Cache.at(cache_dir, remote="")
    result = build(str(SPEC), tmp_path / "trusting", cache=trusting, jobs=1, step=False)
    assert all(f.ok for f in result.findings)  # every check passes on the forged kit
    assert _kit_zip(tmp_path / "trusting") != cold


@pytest.mark.slow
def test_a_forged_emit_entry_with_a_climbing_path_writes_nothing_outside_out(tmp_path):
    from simkit.pipeline import build

    cache_dir, out = tmp_path / "cache", tmp_path / "deep" / "out"
    build(str(SPEC), out, cache=Cache.at(cache_dir, remote=""), jobs=1)
    cold = _kit_zip(out)
    from simkit.kitio.values import decode_json, encode_json

    def add_escape(arrays):
        index = decode_json(arrays["index"])
        end = index[-1][2] if index else 0
        index.append(["../../../escape.txt", end, end + 4])
        arrays["index"] = encode_json(index)
        arrays["blob"] = np.concatenate([arrays["blob"], np.frombuffer(b"evil", np.uint8)])

    for step in ("emit", "simulate"):
        for path in (cache_dir / step).rglob("*.npz"):
            forge(path, add_escape)
    for path in (cache_dir / "zip").rglob("*.npz"):
        path.unlink()
    cache = Cache.at(cache_dir, remote="")
    build(str(SPEC), out, cache=cache, jobs=1)
    assert not list(tmp_path.rglob("escape.txt"))
    assert _kit_zip(out) == cold and cache.stats.repaired == {"emit": 1, "simulate": 1}


def test_cache_dir_env_given_a_url_is_refused(monkeypatch):
    from simkit.errors import SimkitError

    monkeypatch.setenv("SIMKIT_CACHE_DIR", "s3://bucket/prefix")
    with pytest.raises(SimkitError, match=r"^\$SIMKIT_CACHE_DIR s3://bucket/prefix: is a URL"):
        Cache.at()
