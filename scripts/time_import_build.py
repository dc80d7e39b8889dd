"""CPU and wall seconds of `simkit import` + a cold `simkit build` for the given robot files,
with each of several simkit source trees, one command at a time (the same machine state for
every tree: compare trees here, not against another run).

    python scripts/time_import_build.py --src OLD/src --src NEW/src FILE.xml ...
    python scripts/time_import_build.py --pairs [--repeats N] REF.urdf OTHER.sdf|usd ...

With `--pairs` the files are pairs: one robot as its URDF and as another format (issue 39:
an SDF or USD robot within 1.5x of its URDF). Each is imported and cold-built N times
(default 3) with this checkout's src (or the first --src), the pair's runs interleaved so
that load on the machine falls on both alike; per file the median wall and CPU seconds, per
pair the ratio OTHER / REF of the medians (wall, and CPU: the figure load on a shared
machine does not inflate).

CPU seconds are user + system of the two processes and their children (getrusage), which
other work on the machine does not inflate; the load average is taken when each row starts.
No robot is named here."""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


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
    parser.add_argument("--src", action="append", type=Path, help="a src/ tree [this one's]")
    parser.add_argument("--pairs", action="store_true", help="files are REF.urdf OTHER pairs")
    parser.add_argument("--repeats", type=int, default=3, help="runs per file with --pairs")
    parser.add_argument("robots", nargs="+", type=Path)
    args = parser.parse_args()
    args.src = args.src or [REPO / "src"]
    if args.pairs:
        pairs(args.src[0].resolve(), args.robots, args.repeats)
        return
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


def pairs(src: Path, files: list[Path], repeats: int) -> None:
    """Median import + cold build of each file of each (REF, OTHER) pair, and the ratio."""
    if len(files) % 2:
        sys.exit("--pairs: give the files in pairs, REF.urdf OTHER")
    couples = list(zip(files[::2], files[1::2], strict=True))
    runs: dict[Path, list[tuple[float, float]]] = {}
    with tempfile.TemporaryDirectory(prefix="simkit-timing-") as tmp:
        for _ in range(repeats):
            for ref, other in couples:
                for path in (ref, other):
                    cpu, wall, _load, built = one(src, path.resolve(), Path(tmp) / "run")
                    if not built:
                        sys.exit(f"{path}: the import or the build failed")
                    runs.setdefault(path, []).append((wall, cpu))
    for ref, other in couples:
        wall, cpu = {}, {}
        for path in (ref, other):
            wall[path] = statistics.median(w for w, _ in runs[path])
            cpu[path] = statistics.median(c for _, c in runs[path])
            shown = " ".join(f"{w:.1f}" for w, _ in runs[path])
            print(f"{path}: wall {shown} s, median {wall[path]:.1f} s (CPU {cpu[path]:.1f} s)")
        print(
            f"ratio {other.name} / {ref.name}: {wall[other] / wall[ref]:.2f} wall, "
            f"{cpu[other] / cpu[ref]:.2f} CPU",
            flush=True,
        )


if __name__ == "__main__":
    main()
