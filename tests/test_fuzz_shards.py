"""scripts/fuzz_specs.py shards (issue 26): each spec is mutated from its own seed, so a
stopped run resumes where it stopped, shards may run in any order or on Ray, and two runs
with the same seeds give the same outcome table. Validation only: no kit builds."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "fuzz_specs.py"


def _run(work: Path, *args: str) -> dict:
    cmd = [sys.executable, str(SCRIPT), "--validate-only", "--seed", "7", "--work", str(work)]
    subprocess.run([*cmd, *args], check=True, capture_output=True, text=True)
    return json.loads((work / "summary.json").read_text())


def _indices(work: Path) -> list[int]:
    lines = (work / "results.jsonl").read_text().splitlines()
    return sorted(json.loads(line)["index"] for line in lines)


def test_resumed_run_gives_the_table_of_one_run(tmp_path):
    whole = _run(tmp_path / "whole", "--count", "40", "--shard-size", "7")
    _run(tmp_path / "parts", "--count", "15")
    resumed = _run(tmp_path / "parts", "--count", "40", "--resume")
    assert resumed["outcomes"] == whole["outcomes"]
    assert resumed["specs"] == whole["specs"] == 40
    assert _indices(tmp_path / "parts") == list(range(40))  # each spec ran once
    assert _outcomes(tmp_path / "parts") == _outcomes(tmp_path / "whole")


def _outcomes(work: Path) -> dict[int, str]:
    lines = (work / "results.jsonl").read_text().splitlines()
    return {json.loads(line)["index"]: json.loads(line)["outcome"] for line in lines}


@pytest.mark.slow
@pytest.mark.xdist_group("ray")  # with tests/test_ray.py: one local Ray instance at a time
def test_ray_shards_give_the_serial_table(tmp_path):
    pytest.importorskip("ray")
    serial = _run(tmp_path / "serial", "--count", "30", "--shard-size", "4")
    on_ray = _run(tmp_path / "ray", "--count", "30", "--shard-size", "4", "--ray")
    assert on_ray["outcomes"] == serial["outcomes"]
    assert _outcomes(tmp_path / "ray") == _outcomes(tmp_path / "serial")
    assert _indices(tmp_path / "ray") == list(range(30))
