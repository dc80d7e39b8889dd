"""CPU and wall seconds of `simkit import` + a cold `simkit build` for the given robot files,
with each of several simkit source trees, one command at a time (the same machine state for
every tree: compare trees here, not against another run).

    python scripts/time_import_build.py --src OLD/src --src NEW/src FILE.xml ...

CPU seconds are user + system of the two processes and their children (getrusage), which
other work on the machine does not inflate; the load average is taken when each row starts.
No robot is named here."""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _cpu() -> float:
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def one(src: Path, robot: Path, work: Path) -> tuple[float, float, float, bool]:
    """(CPU s, wall s, load average at the start, built) of one import + cold build."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    name = "robot"
    shutil.rmtree(work, ignore_errors=True)
    cpu, start, load = _cpu(), time.perf_counter(), os.getloadavg()[0]
    run = [sys.executable, "-m", "simkit.cli"]
    done = subprocess.run([*run, "import", str(robot), "--name", name, "--out", str(work / "spec")],
                          env=env, capture_output=True)  # fmt: skip
    built = done.returncode == 0
    if built:
        spec = str(work / "spec" / f"{name}.yaml")
        build = [*run, "build", spec, "--out", str(work / "kits"), "--cache-dir", str(work / "c")]
        built = subprocess.run([*build, "-q"], env=env, capture_output=True).returncode == 0
    return _cpu() - cpu, time.perf_counter() - start, load, built


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--src", action="append", type=Path, required=True, help="a src/ tree")
    parser.add_argument("robots", nargs="+", type=Path)
    args = parser.parse_args()
    print("| file | " + " | ".join(f"{s} CPU s / wall s (load)" for s in args.src) + " |")
    print("|---|" + "---|" * len(args.src))
    with tempfile.TemporaryDirectory(prefix="simkit-timing-") as tmp:
        for robot in args.robots:
            cells = []
            for k, src in enumerate(args.src):
                cpu, wall, load, built = one(src.resolve(), robot.resolve(), Path(tmp) / str(k))
                cells.append(f"{cpu:.1f} / {wall:.1f} ({load:.1f})" + ("" if built else " failed"))
            print(f"| {robot.name if robot.name != 'robot.xml' else robot.parent.name} | "
                  + " | ".join(cells) + " |", flush=True)  # fmt: skip


if __name__ == "__main__":
    main()
