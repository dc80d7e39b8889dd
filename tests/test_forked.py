"""kitio/forked.py: work in a forked child gives the in-process value, errors surface here."""

from __future__ import annotations

import os
import sys

import pytest

from simkit.kitio.forked import Background

#: JAX (if an earlier test loaded it) warns at every fork; these forks run only simkit code
pytestmark = pytest.mark.filterwarnings("ignore:os.fork:RuntimeWarning")


@pytest.fixture(autouse=True)
def _no_jax(monkeypatch: pytest.MonkeyPatch) -> None:
    """An earlier test (test_asimov's MJX check) may have loaded JAX, which turns forking
    off; these tests are about forking, so they hide it (its threads are idle by now)."""
    monkeypatch.delitem(sys.modules, "jax", raising=False)


def test_no_fork_where_jax_is_loaded(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "jax", object())
    job = Background(os.getpid)
    assert job._pid == 0 and job.result() == os.getpid()


def test_child_value_comes_back_and_child_is_reaped() -> None:
    job = Background(lambda: (os.getpid(), b"x" * 3_000_000))
    assert job._pid > 0  # really forked
    pid, data = job.result()
    assert pid != os.getpid() and data == b"x" * 3_000_000
    assert job._pid == 0


def test_failure_in_child_is_raised_in_process() -> None:
    calls = []

    def work() -> int:
        calls.append(os.getpid())
        raise ValueError("degenerate solid")

    job = Background(work)
    with pytest.raises(ValueError, match="degenerate solid"):
        job.result()
    assert calls == [os.getpid()]  # the child's call is not seen here; the rerun is


def test_killed_child_falls_back_to_in_process() -> None:
    parent = os.getpid()

    def work() -> int:
        if os.getpid() != parent:  # only the child dies
            os.kill(os.getpid(), 9)
        return os.getpid()

    job = Background(work)
    assert job.result() == parent


def test_no_fork_runs_in_process(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SIMKIT_NO_FORK", "1")
    job = Background(os.getpid)
    assert job._pid == 0 and job.result() == os.getpid()


def test_close_stops_an_unwanted_child() -> None:
    job = Background(lambda: __import__("time").sleep(60))
    pid = job._pid
    job.close()
    assert job._pid == 0
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)


def _pid_and_json_loaded() -> tuple[int, bool]:
    import sys

    return os.getpid(), "json.decoder" in sys.modules


def _fails() -> int:
    raise RuntimeError("bad solid")


def test_warm_worker_runs_jobs_in_one_child_that_imported_first() -> None:
    from simkit.kitio import forked

    with forked.warm_worker(("json",)):
        first = Background(_pid_and_json_loaded).result()
        second = Background(_pid_and_json_loaded).result()
        assert forked._WORKER is not None and forked._WORKER.pid == first[0]
    assert first[0] == second[0] != os.getpid()  # one worker, not this process
    assert first[1]  # the worker imported json before the job came
    assert forked._WORKER is None


def test_warm_worker_failure_is_raised_here_and_unpicklable_work_forks() -> None:
    from simkit.kitio import forked

    with forked.warm_worker(("json",)):
        with pytest.raises(RuntimeError, match="bad solid"):
            Background(_fails).result()
        local = 7
        job = Background(lambda: local * 6)  # a lambda cannot be pickled: a fresh fork runs it
        assert job._worker is None and job._pid > 0
        assert job.result() == 42


def test_run_all_keeps_job_order_and_runs_the_named_jobs_beside() -> None:
    from simkit.kitio.forked import run_all

    jobs = {"a": os.getpid, "b": _pid_and_json_loaded, "c": os.getpid}
    done = run_all(jobs, ("b",))
    assert list(done) == ["a", "b", "c"]
    assert done["a"] == done["c"] == os.getpid() != done["b"][0]  # b ran in a child
