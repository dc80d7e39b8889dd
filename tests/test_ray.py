"""Many robots on Ray (issue 26, simkit/cluster.py), on a real local Ray instance.

A Ray build is byte-identical to a serial one; a worker with another fingerprint is refused
in one line; a task whose worker is killed mid-build is retried, and one killed on every try
is reported in one line; without `--ray`, Ray is never imported.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from simkit.errors import SimkitError
from simkit.kitio.cache import Cache
from simkit.pipeline import build

ray = pytest.importorskip("ray")
psutil = pytest.importorskip("psutil")
#: one pytest-xdist worker runs every test that starts Ray (tests/conftest.py), so two local
#: Ray instances never share the cores while these kill and retry workers
pytestmark = pytest.mark.xdist_group("ray")

SPECS = Path(__file__).resolve().parent / "specs"
#: Two small specs: one of primitives, one naming a mesh file the task must carry along.
TWO = [str(SPECS / "planar_2r.yaml"), str(SPECS / "collision_mix.yaml")]


@pytest.fixture(scope="module")
def local_ray():
    """A local Ray instance of 2 CPUs for this module, shut down after it."""
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, configure_logging=False)
    yield ray
    ray.shutdown()


def _tree(folder: Path) -> dict[str, bytes]:
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


@pytest.mark.slow
def test_two_robots_on_ray_are_byte_identical_to_serial(local_ray, tmp_path):
    from simkit.cluster import build_on_ray

    serial, on_ray = tmp_path / "serial", tmp_path / "ray"
    expected = [build(target, serial) for target in TWO]
    got = build_on_ray(TWO, on_ray)
    assert [r.robot for r in got] == [r.robot for r in expected]
    for want, have in zip(expected, got, strict=True):
        assert have.kit_dir.parent == on_ray
        assert _tree(have.kit_dir) == _tree(want.kit_dir)
        assert have.zip_path.read_bytes() == want.zip_path.read_bytes()
        assert [f.line() for f in have.findings] == [f.line() for f in want.findings]
        assert have.findings and all(f.ok for f in have.findings)


@pytest.mark.slow
def test_spec_error_on_a_worker_is_the_local_one_line(local_ray, tmp_path):
    from simkit.cluster import build_on_ray

    bad = tmp_path / "bad.yaml"
    text = (SPECS / "planar_2r.yaml").read_text().replace("mass: 1.0", "mass: -7.2", 1)
    bad.write_text(text)
    with pytest.raises(SimkitError) as local:
        build(str(bad), tmp_path / "local")
    with pytest.raises(SimkitError) as remote:
        build_on_ray([str(bad)], tmp_path / "remote")
    # the worker's temporary folder is not in the message: the caller's file name is
    assert str(remote.value) == str(local.value).replace(f"{tmp_path}{os.sep}", "")
    assert "\n" not in str(remote.value)
    assert not (tmp_path / "remote" / "planar_2r_description").exists()


@pytest.mark.slow
def test_worker_with_other_versions_is_refused_in_one_line(local_ray, tmp_path, monkeypatch):
    from simkit import cluster

    # The caller's fingerprint changes here only; the Ray worker computes its own.
    monkeypatch.setattr(cluster, "fingerprint", lambda: "0" * 64)
    with pytest.raises(SimkitError) as refused:
        cluster.build_on_ray([TWO[0]], tmp_path / "out")
    message = str(refused.value)
    assert "versions differ from the caller's" in message and "\n" not in message
    assert not (tmp_path / "out" / "planar_2r_description").exists()


def _running_task(proc) -> bool:
    """A Ray worker running `run_job` (Ray sets its title), not a child it forked (the STEP
    worker inherits the title)."""
    try:
        titled = "run_job" in " ".join(proc.cmdline())
        return titled and "run_job" not in " ".join(proc.parent().cmdline())
    except (psutil.Error, AttributeError):
        return False


def _kill_task_workers(stop: threading.Event, kills: list[int], most: int) -> None:
    """Kill -9 every Ray worker process that is running `run_job`, up to `most` times (a sweep
    stops at `most`: a STEP child the killed worker forked, orphaned, looks like a task)."""
    while not stop.is_set() and len(kills) < most:
        for proc in psutil.process_iter(["pid"]):
            if len(kills) >= most:
                break
            if _running_task(proc) and proc.info["pid"] not in kills:
                try:
                    proc.kill()
                    kills.append(proc.info["pid"])
                except psutil.Error:
                    pass
        time.sleep(0.05)


def _build_while_killing(targets, out: Path, most: int) -> tuple[object, list[int]]:
    from simkit.cluster import build_on_ray

    stop, kills = threading.Event(), []
    killer = threading.Thread(target=_kill_task_workers, args=(stop, kills, most))
    killer.start()
    try:
        # no cache: the build takes long enough to be killed mid-way
        return build_on_ray(targets, out, cache=Cache.disabled()), kills
    except SimkitError as exc:
        return exc, kills
    finally:
        stop.set()
        killer.join()


@pytest.mark.slow
def test_task_killed_mid_build_is_retried(local_ray, tmp_path):
    result, kills = _build_while_killing([TWO[0]], tmp_path / "out", most=1)
    assert len(kills) == 1, "the build ended before its worker could be killed"
    assert not isinstance(result, Exception), result
    want = build(TWO[0], tmp_path / "serial")
    assert _tree(result[0].kit_dir) == _tree(want.kit_dir)


@pytest.mark.slow
def test_task_killed_on_every_try_is_one_line(local_ray, tmp_path):
    from simkit.cluster import TASK_RETRIES

    # kill every try (Ray may not count a worker killed before the task began as a try)
    result, kills = _build_while_killing([TWO[0]], tmp_path / "out", most=100)
    assert len(kills) >= TASK_RETRIES + 1
    assert isinstance(result, SimkitError)
    assert f"failed {TASK_RETRIES + 1} times" in str(result) and "\n" not in str(result)
    assert not (tmp_path / "out" / "planar_2r_description").exists()


def test_without_ray_flag_ray_is_not_imported():
    code = (
        "import sys, simkit.cli, simkit.pipeline, simkit.publish\n"
        "from click.testing import CliRunner\n"
        "CliRunner().invoke(simkit.cli.main, ['build', '--help'])\n"
        "assert 'ray' not in sys.modules, 'ray imported'\n"
        "assert 'simkit.cluster' not in sys.modules, 'cluster imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_named_files_are_those_inside_the_spec_folder(tmp_path):
    from simkit.cluster import named_files

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "a.stl").write_bytes(b"solid a")
    (tmp_path.parent / "secret.txt").write_text("no")
    spec = tmp_path / "r.yaml"
    spec.write_text(
        "name: r\nlinks:\n  - solid: [{file: meshes/a.stl}, {file: ../secret.txt}]\n"
        "    note: not a file\n"
    )
    assert named_files(spec) == {"meshes/a.stl": b"solid a"}


@pytest.mark.slow
def test_publish_on_ray_lays_out_the_serial_site(local_ray, tmp_path):
    from simkit.publish import publish

    serial = publish(tmp_path / "serial" / "sim", TWO)
    on_ray = publish(tmp_path / "ray" / "sim", TWO, on_ray=True)
    assert on_ray == serial
    assert _tree(tmp_path / "ray" / "sim") == _tree(tmp_path / "serial" / "sim")


@pytest.mark.slow
def test_workers_use_the_remote_cache_when_one_is_set(local_ray, tmp_path):
    from simkit.cluster import build_on_ray

    remote = tmp_path / "shared"
    args = {"root": str(tmp_path / "worker-cache"), "remote": remote.as_uri()}
    first = build_on_ray([TWO[0]], tmp_path / "a", cache_args=args)
    stored = sorted(p for p in remote.rglob("*") if p.is_file())
    assert stored, "the worker wrote nothing to the remote cache"
    # a worker with an empty local cache takes every stage from the remote one
    args["root"] = str(tmp_path / "fresh-cache")
    second = build_on_ray([TWO[0]], tmp_path / "b", cache_args=args)
    assert _tree(second[0].kit_dir) == _tree(first[0].kit_dir)
    assert sorted(p for p in remote.rglob("*") if p.is_file()) == stored
    # "stage local/remote/miss" per stage: every stage came from the remote cache
    counts = [part.split()[-1].split("/") for part in second[0].cache_hits.split(", ")]
    assert counts and all(c[0] == "0" and c[1] != "0" and c[2] == "0" for c in counts), second[
        0
    ].cache_hits
