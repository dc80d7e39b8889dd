"""The remote cache (issue 26) against a real S3 API: moto's server on 127.0.0.1, started
here on a free port and stopped after. Entries follow the trust rules of issue 24."""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from simkit.kitio.cache import Cache, make_key
from simkit.kitio.entry import decode
from simkit.kitio.remote import CONNECT_TIMEOUT_S, RemoteStore

SPEC = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
ROOT = Path(__file__).resolve().parents[1]
AWS = {
    "AWS_ACCESS_KEY_ID": "testing",
    "AWS_SECRET_ACCESS_KEY": "testing",
    "AWS_DEFAULT_REGION": "us-east-1",
    "AWS_CONFIG_FILE": "/nonexistent/aws-config",
    "AWS_SHARED_CREDENTIALS_FILE": "/nonexistent/aws-credentials",
}
SIMKIT_ENV = ("SIMKIT_CACHE_KEY", "SIMKIT_REMOTE_CACHE", "SIMKIT_CACHE_READONLY")


@pytest.fixture(scope="module")
def endpoint():
    """moto's S3 server on a free port of 127.0.0.1, for this module."""
    from moto.server import ThreadedMotoServer

    server = ThreadedMotoServer(ip_address="127.0.0.1", port=0, verbose=False)
    server.start()
    host, port = server.get_host_and_port()
    yield f"http://{host}:{port}"
    server.stop()


def _bucket(endpoint: str, name: str) -> None:
    import boto3

    boto3.client("s3", endpoint_url=endpoint, **_creds()).create_bucket(Bucket=name)


def _creds() -> dict:
    return {
        "aws_access_key_id": "testing",
        "aws_secret_access_key": "testing",
        "region_name": "us-east-1",
    }


@pytest.fixture
def s3(endpoint, monkeypatch, request):
    """`s3://BUCKET/cache` in a fresh bucket, with this process's AWS env pointing at moto."""
    for name, value in {**AWS, "AWS_ENDPOINT_URL": endpoint}.items():
        monkeypatch.setenv(name, value)
    for name in SIMKIT_ENV:
        monkeypatch.delenv(name, raising=False)
    bucket = re.sub(r"[^a-z0-9]", "-", request.node.name.lower())[:50].strip("-")
    _bucket(endpoint, bucket)
    return f"s3://{bucket}/cache"


def _objects(url: str) -> dict[str, bytes]:
    import fsspec

    fs, root = fsspec.core.url_to_fs(url, skip_instance_cache=True, use_listings_cache=False)
    return {p: fs.cat_file(p) for p in sorted(fs.find(root))}


def _closed_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _warnings(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith("simkit: warning:")]


KEY = make_key("s", 1, [b"a"], {})


def test_conditional_put_is_write_once(s3):
    store = RemoteStore(s3, print)
    store.store("s", KEY, b"first")
    store.store("s", KEY, b"second")
    assert store.conditional is True
    assert _objects(s3) == {f"{s3[5:]}/s/{KEY[:2]}/{KEY}.npz": b"first"}


def test_temporary_key_and_copy_is_write_once(s3):
    store = RemoteStore(s3, print, conditional=False)
    store.store("s", KEY, b"first")
    store.store("s", KEY, b"second")
    assert _objects(s3) == {f"{s3[5:]}/s/{KEY[:2]}/{KEY}.npz": b"first"}  # no tmp/ left
    store.store("s", KEY, b"verified", replace=True)  # the one overwrite allowed
    assert list(_objects(s3).values()) == [b"verified"]


def test_any_fsspec_store_serves_as_the_remote(tmp_path):
    """S3 is the tested store; the same code writes once to another fsspec store."""
    url = f"file://{tmp_path / 'shared'}"
    Cache.at(tmp_path / "a", readonly=False, remote=url).put("s", KEY, {"v": np.arange(3.0)})
    Cache.at(tmp_path / "x", readonly=False, remote=url).put("s", KEY, {"v": np.arange(9.0)})
    b = Cache.at(tmp_path / "b", readonly=False, remote=url)
    np.testing.assert_array_equal(b.get("s", KEY)["v"], np.arange(3.0))
    assert b.stats.remote == {"s": 1}


def test_local_cache_stays_in_front_of_the_remote(s3, tmp_path):
    Cache.at(tmp_path / "a", readonly=False, remote=s3).put("s", KEY, {"v": np.arange(3.0)})
    b = Cache.at(tmp_path / "b", readonly=False, remote=s3)
    np.testing.assert_array_equal(b.get("s", KEY)["v"], np.arange(3.0))
    assert b.stats.remote == {"s": 1} and b.path("s", KEY).is_file()
    again = Cache.at(tmp_path / "b", readonly=False, remote=s3)
    assert again.get("s", KEY) is not None and again.stats.hits == {"s": 1}
    assert again.stats.summary() == "s 1/0/0" and b.stats.summary() == "s 0/1/0"


def test_a_corrupt_remote_entry_is_one_warning_then_replaced(s3, tmp_path, capsys):
    Cache.at(tmp_path / "a", readonly=False, remote=s3).put("s", KEY, {"v": np.arange(3.0)})
    import fsspec

    fs, _ = fsspec.core.url_to_fs(s3, skip_instance_cache=True)
    (path,) = _objects(s3)
    data = bytearray(fs.cat_file(path))
    data[len(data) // 2] ^= 0xFF
    fs.pipe_file(path, bytes(data))
    c = Cache.at(tmp_path / "c", readonly=False, remote=s3)
    assert c.get("s", KEY) is None and c.get("s", KEY) is None
    assert len(_warnings(capsys.readouterr().err)) == 1
    c.put("s", KEY, {"v": np.arange(3.0)})  # the verified result replaces the bad entry
    np.testing.assert_array_equal(decode(fs.cat_file(path), "s", KEY, None)["v"], np.arange(3.0))


def test_keyed_readers_refuse_untagged_remote_entries(s3, tmp_path, monkeypatch, capsys):
    Cache.at(tmp_path / "untrusted", readonly=False, remote=s3).put("s", KEY, {"v": np.ones(3)})
    monkeypatch.setenv("SIMKIT_CACHE_KEY", "k")
    keyed = Cache.at(tmp_path / "keyed", readonly=False, remote=s3)
    assert keyed.get("s", KEY) is None
    assert len(_warnings(capsys.readouterr().err)) == 1
    keyed.put("s", KEY, {"v": np.zeros(3)})  # a keyed writer replaces it with a tagged entry
    fresh = Cache.at(tmp_path / "fresh", readonly=False, remote=s3)
    np.testing.assert_array_equal(fresh.get("s", KEY)["v"], np.zeros(3))


def test_readonly_runner_reads_and_writes_nothing(s3, tmp_path):
    Cache.at(tmp_path / "a", readonly=False, remote=s3).put("s", KEY, {"v": np.arange(3.0)})
    before = _objects(s3)
    pr = Cache.at(tmp_path / "pr", readonly=True, remote=s3)
    assert pr.get("s", KEY) is not None and pr.stats.remote == {"s": 1}
    pr.put("s", make_key("s", 1, [b"other"], {}), {"v": np.arange(2.0)})
    assert _objects(s3) == before and not (tmp_path / "pr").exists()


def test_an_unreachable_store_is_one_warning_and_the_local_cache(tmp_path, monkeypatch, capsys):
    for name, value in AWS.items():
        monkeypatch.setenv(name, value)
    monkeypatch.setenv("AWS_ENDPOINT_URL", f"http://127.0.0.1:{_closed_port()}")
    start = time.monotonic()
    cache = Cache.at(tmp_path / "c", readonly=False, remote="s3://nowhere/cache")
    for i in range(3):
        key = make_key("s", 1, [bytes([i])], {})
        assert cache.get("s", key) is None
        cache.put("s", key, {"v": np.arange(3.0)})
        assert cache.get("s", key) is not None  # the local cache still serves
    assert time.monotonic() - start < 2 * CONNECT_TIMEOUT_S
    (line,) = _warnings(capsys.readouterr().err)
    assert "unreachable" in line and "local cache only" in line


def test_a_store_refusing_writes_is_one_warning(s3, tmp_path, capsys):
    url = s3.replace(s3.split("/")[2], "no-such-bucket")  # every put is refused
    cache = Cache.at(tmp_path / "c", readonly=False, remote=url)
    for i in range(3):
        cache.put("s", make_key("s", 1, [bytes([i])], {}), {"v": np.arange(3.0)})
    (line,) = _warnings(capsys.readouterr().err)
    assert "refused a write" in line
    assert cache.get("s", make_key("s", 1, [b"\0"], {})) is not None


@pytest.mark.slow
def test_a_dead_endpoint_cannot_stall_a_build(tmp_path, monkeypatch, capsys):
    """A server whose accept queue is full never answers a SYN: the connect timeout (at
    most 10 s) bounds the wait, once, as the store is then dropped."""
    server = socket.socket()
    server.bind(("127.0.0.1", 0))
    server.listen(0)
    port = server.getsockname()[1]
    fillers = []
    for _ in range(8):
        sock = socket.socket()
        sock.setblocking(False)
        sock.connect_ex(("127.0.0.1", port))
        fillers.append(sock)
    for name, value in {**AWS, "AWS_ENDPOINT_URL": f"http://127.0.0.1:{port}"}.items():
        monkeypatch.setenv(name, value)
    try:
        cache = Cache.at(tmp_path / "c", readonly=False, remote="s3://dead/cache")
        start = time.monotonic()
        assert cache.get("s", KEY) is None and cache.get("s", make_key("s", 1, [], {})) is None
        assert time.monotonic() - start < 2 * 10 + 2
        assert len(_warnings(capsys.readouterr().err)) == 1
    finally:
        for sock in [*fillers, server]:
            sock.close()


def test_plain_install_pulls_no_remote_or_cluster_library():
    """`pip install .` installs [project].dependencies and what they require (no extras):
    the closure, read from the installed metadata, holds none of the optional libraries."""
    from importlib import metadata

    from packaging.requirements import Requirement

    tomllib = pytest.importorskip("tomllib")  # Python 3.11+

    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    todo = [Requirement(r).name for r in project["dependencies"]]
    seen: set[str] = set()
    while todo:
        name = todo.pop().lower().replace("_", "-")
        if name in seen:
            continue
        seen.add(name)
        for text in metadata.requires(name) or []:
            req = Requirement(text)
            if req.marker is None or req.marker.evaluate({"extra": ""}):
                todo.append(req.name)
    assert "numpy" in seen and len(seen) > 20
    assert not seen & {"fsspec", "s3fs", "moto", "ray", "boto3", "botocore", "aiobotocore"}
    remote = project["optional-dependencies"]["remote"]
    assert {"fsspec", "s3fs"} <= {Requirement(r).name for r in remote}


# --- runners: separate processes, each with its own HOME, working folder and cache -------


def _runner(tmp: Path, name: str, endpoint: str, *args: str, key: str | None = "k", **env):
    home, work, cache = (tmp / name / part for part in ("home", "work", "cache"))
    for folder in (home, work):
        folder.mkdir(parents=True)
    full = {k: v for k, v in os.environ.items() if k not in SIMKIT_ENV}
    full.update(AWS, AWS_ENDPOINT_URL=endpoint, HOME=str(home), SIMKIT_CACHE_DIR=str(cache))
    full.update(env)
    if key:
        full["SIMKIT_CACHE_KEY"] = key
    cmd = [sys.executable, "-m", "simkit.cli", "build", str(SPEC), "--out", "out", *args]
    proc = subprocess.run(cmd, capture_output=True, text=True, cwd=work, env=full, timeout=600)
    assert proc.returncode == 0, proc.stderr
    (summary,) = re.findall(r"cache local/remote/miss: (.*)$", proc.stdout, re.M)
    counts = {
        step: tuple(int(n) for n in nums.split("/"))
        for step, nums in (item.split(" ") for item in summary.split(", "))
    }
    (zip_path,) = (work / "out").glob("*.zip")
    return counts, zip_path.read_bytes(), proc.stderr, cache


@pytest.fixture(scope="module")
def runner_a(endpoint, tmp_path_factory):
    """A trusted runner's cold build into a shared bucket (key set)."""
    _bucket(endpoint, "fleet")
    tmp = tmp_path_factory.mktemp("fleet")
    counts, kit, err, _ = _runner(tmp, "a", endpoint, "--remote-cache", "s3://fleet/cache")
    assert all(local == remote == 0 for local, remote, _ in counts.values()), counts
    assert _warnings(err) == []
    return counts, kit


@pytest.mark.slow
def test_runner_b_hits_every_cached_stage_remotely(endpoint, runner_a, tmp_path):
    counts_a, kit_a = runner_a
    counts, kit, err, _ = _runner(
        tmp_path, "b", endpoint, key="k", SIMKIT_REMOTE_CACHE="s3://fleet/cache"
    )
    assert counts == {step: (0, miss, 0) for step, (_, _, miss) in counts_a.items()}
    assert kit == kit_a and _warnings(err) == []


@pytest.mark.slow
def test_pull_request_runner_reads_and_writes_nothing(endpoint, runner_a, tmp_path, monkeypatch):
    for name, value in {**AWS, "AWS_ENDPOINT_URL": endpoint}.items():
        monkeypatch.setenv(name, value)
    before = _objects("s3://fleet/cache")
    counts, kit, err, cache = _runner(
        tmp_path, "pr", endpoint, "--cache-readonly", "--remote-cache", "s3://fleet/cache", key=None
    )
    assert kit == runner_a[1] and _warnings(err) == []
    assert all(miss == 0 and local == 0 for local, _, miss in counts.values()), counts
    assert _objects("s3://fleet/cache") == before and not cache.exists()


@pytest.mark.slow
def test_corrupt_remote_entry_gives_one_warning_and_a_correct_kit(
    endpoint, runner_a, tmp_path, monkeypatch
):
    import fsspec

    for name, value in {**AWS, "AWS_ENDPOINT_URL": endpoint}.items():
        monkeypatch.setenv(name, value)
    fs, _ = fsspec.core.url_to_fs("s3://fleet/cache", skip_instance_cache=True)
    (path,) = [p for p in _objects("s3://fleet/cache") if "/zip/" in p]
    fs.pipe_file(path, b"not an npz")
    args = ("--remote-cache", "s3://fleet/cache")
    counts, kit, err, _ = _runner(tmp_path, "c", endpoint, *args)
    assert kit == runner_a[1] and len(_warnings(err)) == 1 and counts["zip"] == (0, 0, 1)
    counts, kit, err, _ = _runner(tmp_path, "d", endpoint, *args)  # repaired for the fleet
    assert counts["zip"] == (0, 1, 0) and kit == runner_a[1] and _warnings(err) == []


@pytest.mark.slow
def test_unreachable_store_gives_one_warning_and_a_correct_kit(runner_a, tmp_path):
    dead = f"http://127.0.0.1:{_closed_port()}"
    counts, kit, err, _ = _runner(tmp_path, "e", dead, "--remote-cache", "s3://fleet/cache")
    assert kit == runner_a[1] and len(_warnings(err)) == 1 and "unreachable" in err
    assert all(remote == 0 for _, remote, _ in counts.values())


def test_without_a_remote_url_fsspec_is_not_imported(tmp_path):
    script = (
        "import sys\n"
        "from simkit.kitio.cache import Cache, make_key\n"
        f"c = Cache.at({str(tmp_path)!r}, remote='')\n"
        "c.put('s', make_key('s', 1, [], {}), {})\n"
        "print(sorted(m for m in ('fsspec', 's3fs', 'botocore') if m in sys.modules))\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in SIMKIT_ENV}
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env)
    assert proc.returncode == 0 and proc.stdout.strip() == "[]", proc.stderr
