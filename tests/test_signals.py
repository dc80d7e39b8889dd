"""SIGTERM and SIGINT end `simkit build`, `publish` and `import` through their clean-up
(kitio/interrupt.py), and a full disk is one line (issue 24, "Disk and I/O failures").

Real `python -m simkit.cli` subprocesses: the signal is sent once the command's staging
folder exists; then the exit code is 128 + the signal, stderr is one line, no staging or
temporary folder is left in --out, $TMPDIR or the cache, no child process is left (each run
carries a tag in its environment, which forked children inherit), and the previous output
is byte for byte as it was. Synthetic publishes signal themselves at every step of the
commit (`SIMKIT_TEST_SIGNAL_AT`): the kit and zip are always of one build.
"""

from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from simkit.kitio import atomic, layout

HERE = Path(__file__).resolve().parent
SPEC = HERE / "specs" / "planar_2r.yaml"
SRC = str(HERE.parent / "src")
TAG = "SIMKIT_TEST_SIGNALS_TAG"
SIGNALS = [signal.SIGTERM, signal.SIGINT]

pytestmark = pytest.mark.skipif(not Path("/proc/self/environ").exists(), reason="needs /proc")


def _env(tmp: Path, tag: str) -> dict[str, str]:
    (tmp / "tmp").mkdir(exist_ok=True)
    env = {**os.environ, "TMPDIR": str(tmp / "tmp"), "SIMKIT_CACHE_DIR": str(tmp / "cache")}
    for name in (atomic.KILL_ENV, atomic.SIGNAL_ENV, "SIMKIT_NO_FORK", "SIMKIT_CACHE_READONLY"):
        env.pop(name, None)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [SRC, env.get("PYTHONPATH")]))
    env[TAG] = tag
    return env


def _tagged(tag: str) -> list[int]:
    """Live processes whose environment carries `tag` (a run's forked children do)."""
    marker = f"{TAG}={tag}".encode()
    found = []
    for proc in Path("/proc").iterdir():
        if proc.name.isdigit():
            try:
                env = (proc / "environ").read_bytes()
            except OSError:
                continue
            if marker in env.split(b"\0"):
                found.append(int(proc.name))
    return found


def _snapshot(root: Path) -> dict[str, bytes | None]:
    """Every path under `root` (hidden ones included): file bytes, None for a folder."""
    return {
        str(p.relative_to(root)): (p.read_bytes() if p.is_file() else None)
        for p in sorted(root.rglob("*"))
    }


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "simkit.cli", *args]


def _interrupt(cmd: list[str], env: dict, staged, sig: int, cwd: Path, settle: float = 0.0):
    """Run `cmd`, send `sig` `settle` seconds after `staged()` lists a staging folder;
    (proc, stderr)."""
    proc = subprocess.Popen(
        cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True
    )
    deadline = time.monotonic() + 240
    while not staged() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.002)
    time.sleep(settle)
    assert proc.poll() is None, "the command ended before its staging folder was seen"
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    return proc, err


def _assert_cleaned(proc, err: str, sig: int, tmp: Path, tag: str) -> None:
    assert proc.returncode == 128 + sig, (proc.returncode, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and signal.Signals(sig).name in lines[0], err
    assert list((tmp / "tmp").iterdir()) == []  # $TMPDIR
    cache = tmp / "cache"
    leftovers = [p for p in cache.rglob("*") if p.name.endswith((".tmp", ".staging"))]
    assert leftovers == []
    assert _tagged(tag) == []  # no forked worker outlived the command


@pytest.fixture(scope="module")
def built(tmp_path_factory) -> Path:
    """planar_2r built once, its cache warm (copied into each test)."""
    root = tmp_path_factory.mktemp("signals")
    env = _env(root, "fixture")
    for cmd in (
        _cli("build", str(SPEC), "--out", str(root / "kit"), "-q"),
        _cli("publish", str(SPEC), "--out", str(root / "pub" / "site"), "-q"),
    ):
        subprocess.run(cmd, env=env, cwd=root, check=True, capture_output=True, timeout=600)
    return root


def _setup(built: Path, tmp: Path, *names: str) -> str:
    for name in ("cache", *names):
        shutil.copytree(built / name, tmp / name, symlinks=True)
    return uuid.uuid4().hex


@pytest.mark.slow
@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: s.name)
def test_build_interrupted_while_staging_cleans_up_and_keeps_the_kit(built, tmp_path, sig):
    tag = _setup(built, tmp_path, "kit")
    out = tmp_path / "kit"
    before = _snapshot(out)
    cmd = _cli("build", str(SPEC), "--out", str(out), "--no-cache", "-q")
    proc, err = _interrupt(
        cmd, _env(tmp_path, tag), lambda: list(out.glob(".*.staging")), sig, tmp_path
    )
    _assert_cleaned(proc, err, sig, tmp_path, tag)
    assert _snapshot(out) == before  # no staging folder, the kit and zip as they were


@pytest.mark.slow
@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: s.name)
def test_publish_interrupted_while_staging_cleans_up_and_keeps_the_site(built, tmp_path, sig):
    tag = _setup(built, tmp_path, "pub")
    pub = tmp_path / "pub"
    before = _snapshot(pub)
    cmd = _cli("publish", str(SPEC), "--out", str(pub / "site"), "-q")
    proc, err = _interrupt(
        cmd, _env(tmp_path, tag), lambda: list(pub.glob(".site.*.staging")), sig, tmp_path
    )
    _assert_cleaned(proc, err, sig, tmp_path, tag)
    assert _snapshot(pub) == before


def _chain_urdf(path: Path, links: int) -> None:
    """A URDF chain of `links` cylinders on revolute joints (imports in about a second)."""
    body = []
    for i in range(links):
        shape = '<geometry><cylinder radius="0.04" length="0.2"/></geometry>'
        body.append(
            f'<link name="l{i}"><inertial><origin xyz="0 0 0.1"/><mass value="1.0"/>'
            '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
            f'<visual><origin xyz="0 0 0.1"/>{shape}</visual>'
            f'<collision><origin xyz="0 0 0.1"/>{shape}</collision></link>'
        )
        if i:
            axis = "0 1 0" if i % 2 else "0 0 1"
            body.append(
                f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
                f'<child link="l{i}"/><origin xyz="0 0 0.2"/><axis xyz="{axis}"/>'
                '<limit lower="-1.5" upper="1.5" effort="10" velocity="1"/></joint>'
            )
    path.write_text(
        '<?xml version="1.0"?>\n<robot name="chain">\n' + "\n".join(body) + "\n</robot>\n"
    )


@pytest.mark.parametrize("sig", [*SIGNALS, signal.SIGHUP], ids=lambda s: s.name)
def test_import_interrupted_while_staging_cleans_up_and_keeps_the_spec(tmp_path, sig):
    urdf = tmp_path / "chain.urdf"
    _chain_urdf(urdf, 30)
    out, tag = tmp_path / "imported", uuid.uuid4().hex
    env = _env(tmp_path, tag)
    cmd = _cli("import", str(urdf), "--out", str(out), "-q")
    subprocess.run(cmd, env=env, cwd=tmp_path, check=True, capture_output=True, timeout=300)
    before = _snapshot(out)
    assert "chain.yaml" in before
    # settle: a signal within microseconds of the mkdir, before `tempfile.TemporaryDirectory`
    # has registered its clean-up, can leave the folder (importer/__init__.py; reported)
    staged = lambda: list(out.glob(".import-*"))  # noqa: E731
    proc, err = _interrupt(cmd, env, staged, sig, tmp_path, settle=0.05)
    _assert_cleaned(proc, err, sig, tmp_path, tag)
    assert _snapshot(out) == before


def _full_disk() -> None:
    """A full disk, as tests/test_cache_keyed.py makes it: files stop at 32 KiB."""
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (32768, 32768))


@pytest.mark.slow
@pytest.mark.parametrize("command", ["build", "publish"])
def test_a_full_disk_is_one_line_naming_the_path_and_keeps_the_output(built, tmp_path, command):
    tag = _setup(built, tmp_path, "kit" if command == "build" else "pub")
    spec = tmp_path / SPEC.name  # another title: the zip and robot.json must be rewritten
    spec.write_text(SPEC.read_text().replace("title: Planar 2R\n", "title: Planar 2R full\n"))
    if command == "build":
        watched = out = tmp_path / "kit"
        args = ["--no-cache"]
    else:
        watched, out = tmp_path / "pub", tmp_path / "pub" / "site"
        args = ["--cache-readonly"]
    before = _snapshot(watched)
    proc = subprocess.run(
        _cli(command, str(spec), "--out", str(out), "-q", *args),
        env=_env(tmp_path, tag),
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
        preexec_fn=_full_disk,
    )
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert str(watched) in lines[0] and "File too large" in lines[0]
    assert _snapshot(watched) == before  # nothing half-written, no staging folder
    assert list((tmp_path / "tmp").iterdir()) == [] and _tagged(tag) == []


#: A synthetic publish (tests/test_atomic.py's, files named by `tag`) under the CLI's
#: handlers; argv[3] == "0" takes renameat2 away.
PUBLISH = """
import sys
from pathlib import Path
from simkit.kitio import atomic, interrupt, layout, manifest
from simkit.kitio.archive import zip_bytes
out, tag = Path(sys.argv[1]), sys.argv[2]
if sys.argv[3] == "0":
    atomic._exchange = lambda a, b: False
files = {"robot.json": tag.encode(), f"meshes/{tag}.stl": tag.encode() * 100}
zip_data = zip_bytes(files, layout.kit_dir_name("toy"))
with interrupt.installed(), atomic.locked(out):
    atomic.repair(out, "toy")
    with atomic.staging_area(out, "toy") as staged:
        atomic.stage_kit(staged, out, "toy", files)
        atomic.stage_file(staged, out, layout.zip_name("toy"), zip_data)
        atomic.stage_file(staged, out, manifest.name("toy"), manifest.make("toy", files, zip_data))
        atomic.commit(staged, out, "toy")
"""
COMMIT_STEPS = [s for s in atomic.STEPS if s != "locked"]


def _toy(out: Path, tag: str, exchange: bool, signal_at: str | None = None):
    env = _env(out.parent, "toy")
    if signal_at:
        env[atomic.SIGNAL_ENV] = signal_at
    cmd = [sys.executable, "-c", PUBLISH, str(out), tag, "1" if exchange else "0"]
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("exchange", [True, False], ids=["renameat2", "two_renames"])
@pytest.mark.parametrize("step", COMMIT_STEPS)
def test_sigterm_at_each_commit_step_leaves_one_whole_build(tmp_path, step, exchange):
    """Before the journal: the old kit and zip, no staging. From the journal on, the commit
    finishes first: the new kit and zip, no journal. Never a mix."""
    from simkit.kitio.archive import read_zip

    if exchange and step == "kit_aside":
        pytest.skip("only without renameat2")
    out = tmp_path / "out"
    assert _toy(out, "old", exchange).returncode == 0
    proc = _toy(out, "new", exchange, signal_at=step)
    assert proc.returncode == 128 + signal.SIGTERM, proc.stderr
    kit = out / layout.kit_dir_name("toy")
    tag = (kit / "robot.json").read_text()
    assert sorted(p.name for p in kit.rglob("*.stl")) == [f"{tag}.stl"]
    zipped = read_zip((out / layout.zip_name("toy")).read_bytes())
    assert sorted(zipped) == [f"meshes/{tag}.stl", "robot.json"]
    assert zipped["robot.json"] == tag.encode()
    assert tag == ("old" if COMMIT_STEPS.index(step) < COMMIT_STEPS.index("journaled") else "new")
    hidden = sorted(p.name for p in out.iterdir() if p.name.startswith("."))
    assert hidden == [".toy.manifest.json"]  # no journal, staging or trash folder


#: `simkit publish`'s folder swap (`atomic.swap_folder`) signalled at each of its steps.
SWAP = """
import shutil, sys
from pathlib import Path
from simkit.kitio import atomic, interrupt
final, tag = Path(sys.argv[1]), sys.argv[2]
if sys.argv[3] == "0":
    atomic._exchange = lambda a, b: False
staged = final.with_name(f".{final.name}.x.staging")
atomic.recover_folder(final)
staged.mkdir()
(staged / "index.json").write_text(tag)
with interrupt.installed():
    try:
        atomic.swap_folder(staged, final)
    finally:
        shutil.rmtree(staged, ignore_errors=True)
"""


@pytest.mark.parametrize("exchange", [True, False], ids=["renameat2", "two_renames"])
@pytest.mark.parametrize("step", atomic.FOLDER_STEPS)
def test_sigterm_during_the_site_swap_leaves_one_whole_site(tmp_path, step, exchange):
    if exchange and step == "site_moved_aside":
        pytest.skip("only without renameat2")
    site = tmp_path / "site"
    env = _env(tmp_path, "swap")
    cmd = [sys.executable, "-c", SWAP, str(site), "old", "1" if exchange else "0"]
    assert subprocess.run(cmd, env=env, timeout=60).returncode == 0
    env[atomic.SIGNAL_ENV] = step
    cmd[4] = "new"
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM, proc.stderr
    expected = "old" if step == "site_staged" else "new"
    assert (site / "index.json").read_text() == expected
    assert sorted(p.name for p in tmp_path.iterdir()) == ["site", "tmp"]


@pytest.mark.parametrize("command", ["build", "publish", "import"])
def test_an_unwritable_out_is_one_line_naming_the_path(tmp_path, command):
    """--out below a plain file (no folder can be made there, root or not): one line naming
    the path, no traceback, nothing written."""
    blocker = tmp_path / "a_file"
    blocker.write_text("x")
    urdf = tmp_path / "chain.urdf"
    _chain_urdf(urdf, 2)
    source = str(urdf if command == "import" else SPEC)
    extra = ["--no-cache"] if command == "build" else ["--cache-readonly"] * (command == "publish")
    proc = subprocess.run(
        _cli(command, source, "--out", str(blocker / "out"), "-q", *extra),
        env=_env(tmp_path, uuid.uuid4().hex),
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert str(blocker) in lines[0], lines[0]
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == ["a_file", "chain.urdf", "tmp"], left


#: A process pool as `derive/per_link.py` runs CoACD in (spawned workers; `shutdown` in a
#: `finally`), its one job far longer than the test waits.
POOL = """
import multiprocessing, sys, time
from concurrent.futures import ProcessPoolExecutor
from simkit.kitio import interrupt
with interrupt.installed():
    pool = ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"))
    try:
        future = pool.submit(time.sleep, 120)
        print("submitted", flush=True)
        future.result()
    finally:
        pool.shutdown(cancel_futures=True)
"""


def test_sigterm_ends_pool_workers_instead_of_waiting_for_their_jobs(tmp_path):
    """Without ending them, `shutdown` waits for the running job (120 s here)."""
    tag = uuid.uuid4().hex
    proc = subprocess.Popen(
        [sys.executable, "-c", POOL],
        env=_env(tmp_path, tag),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout.readline().strip() == "submitted"
    deadline = time.monotonic() + 60
    while len(_tagged(tag)) < 2 and time.monotonic() < deadline:  # the worker has started
        time.sleep(0.02)
    time.sleep(2.0)  # and is past its start-up (a spawned child on a loaded machine)
    start = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    try:
        _, err = proc.communicate(timeout=60)
    finally:
        proc.kill()
    assert time.monotonic() - start < 60
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert _tagged(tag) == []


@pytest.mark.slow
def test_ctrl_c_stops_the_viewer_cleanly(built, tmp_path):
    """Ctrl-C is how `simkit view` stops: exit 0, no interrupted line, no traceback."""
    kit = built / "kit" / "planar_2r_description"
    cmd = _cli("view", str(kit), "--no-browser", "--port", "0")
    proc = subprocess.Popen(
        cmd, env=_env(tmp_path, "view"), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    line = proc.stderr.readline()  # "viewing ... (Ctrl-C stops)": the server is up
    assert "Ctrl-C stops" in line, line
    proc.send_signal(signal.SIGINT)
    _out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, (proc.returncode, err)
    assert "Traceback" not in err and "interrupted" not in err, err
