"""Time `simkit build` per robot: cold (empty cache), warm (cache hit) and no-op, as issues 3
and 23 ask.

For each robot: one cold build into an empty cache folder and an empty output folder; then
`--warm` warm builds, each into a fresh output folder (a full build whose steps all hit the
cache); then `--noop` rebuilds into the cold build's folder, which change nothing (the no-op
of kitio/noop.py). Medians are reported, with CPU seconds (user + system of the build and its
child processes), each build as its own `simkit build` process, so interpreter start-up and
imports count as a user sees them. Also reported: the CoACD share of the cold build (seconds
of the links CoACD decomposed, from the build's plain log lines, over the cold wall time),
collision pieces, and visual and collision triangles.

    python scripts/bench.py                      # every robots/rosie_*.yaml
    python scripts/bench.py rosie_1000 tests/specs/collision_mix.yaml --warm 5 --json out.json
    python scripts/bench.py rosie_1000 --compare-step 3   # what the STEP assembly adds
    python scripts/bench.py rosie_1000 /tmp/imported/humanoid.yaml --warm 1 --noop 5
    python scripts/bench.py --step-rate build/rosie_1000_description/mjcf/rosie_1000.xml OTHER.xml

`--step-rate MJCF ...` instead times C MuJoCo stepping each model file (issue 30): single
thread, from its first keyframe (or qpos0) with the servos holding it, `STEP_RATE_STEPS`
steps a round, the rounds of all the files interleaved so that they share the machine's state
(median steps/s).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

#: CPU seconds (user + system, the build and its worker processes) of each `_build`, in order.
CPU: list[float] = []
LOG = re.compile(r"collision (\S+): (\w+), (\d+) pieces, ([\d.]+) s")


def _build(
    target: str, out: Path, cache: Path, jobs: int | None, extra: tuple[str, ...] = ()
) -> tuple[float, str, str]:
    cmd = [
        sys.executable,
        "-m",
        "simkit.cli",
        "build",
        target,
        "--out",
        str(out),
        "--cache-dir",
        str(cache),
    ]
    if jobs:
        cmd += ["--jobs", str(jobs)]
    cmd += list(extra)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    CPU.append(sum(getattr(after, f) - getattr(before, f) for f in ("ru_utime", "ru_stime")))
    if done.returncode != 0:
        raise SystemExit(f"{target}: build failed:\n{done.stderr}")
    return wall, done.stderr, done.stdout


def _triangles(path: Path) -> int:
    """Triangles of a kit mesh: a binary STL's count, or an OBJ's `f` lines (collision)."""
    data = path.read_bytes()
    if path.suffix == ".obj":
        return sum(line.startswith(b"f ") for line in data.splitlines())
    return int.from_bytes(data[80:84], "little")


def bench(
    target: str,
    warm_runs: int,
    jobs: int | None,
    extra: tuple[str, ...] = (),
    noop_runs: int = 0,
) -> dict:
    with tempfile.TemporaryDirectory(prefix="simkit-bench-") as tmp:
        root = Path(tmp)
        cold, log, _ = _build(target, root / "out", root / "cache", jobs, extra)
        cold_cpu = CPU[-1]
        warm = [
            _build(target, root / f"warm{i}", root / "cache", jobs, extra)[0]
            for i in range(warm_runs)
        ]
        warm_cpu = statistics.median(CPU[-warm_runs:]) if warm_runs else float("nan")
        noop = []
        for _ in range(noop_runs):
            wall, _, said = _build(target, root / "out", root / "cache", jobs, extra)
            if "nothing changed" not in said:
                raise SystemExit(f"{target}: a rebuild with nothing changed was no no-op: {said}")
            noop.append(wall)
        noop_cpu = statistics.median(CPU[-noop_runs:]) if noop_runs else float("nan")
        coacd = sum(float(m[3]) for m in LOG.findall(log) if m[1] == "coacd")
        kit = next((root / "out").glob("*_description"))
        doc = json.loads((kit / "robot.json").read_text())
        visual = sum(
            _triangles(kit / link["mesh"]["visual"])
            for link in doc["links"]
            if link["mesh"]["visual"]
        )
        collision = sum(
            _triangles(kit / p) for link in doc["links"] for p in link["mesh"]["collision"]
        )
        reports = [g["collision"] for g in doc["geometry"]["links"]]
    return {
        "robot": doc["name"],
        "cold_s": cold,
        "warm_s": statistics.median(warm) if warm else float("nan"),
        "warm_runs_s": warm,
        "cold_cpu_s": cold_cpu,
        "warm_cpu_s": warm_cpu,
        "noop_s": statistics.median(noop) if noop else float("nan"),
        "noop_runs_s": noop,
        "noop_cpu_s": noop_cpu,
        "coacd_links": sum(r["method"] == "coacd" for r in reports),
        "coacd_s": coacd,
        "coacd_share": coacd / cold,
        "pieces": sum(r["pieces"] for r in reports),
        "max_pieces_per_link": max(r["pieces"] for r in reports),
        "max_hull_volume_ratio": max(
            r["hull_volume_ratio"] for r in reports if "hull_volume_ratio" in r
        ),
        "max_visual_to_collision_mm": 1000
        * max(r.get("visual_to_collision_max_m", 0.0) for r in reports),
        "visual_triangles": visual,
        "collision_triangles": collision,
    }


STEP_RATE_STEPS = 20_000
STEP_RATE_ROUNDS = 7


def _step_once(path: Path) -> float:
    """Steps per second of one round of C MuJoCo on the model file."""
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    if model.nkey:
        mujoco.mj_resetDataKeyframe(model, data, 0)
    start = time.perf_counter()
    for _ in range(STEP_RATE_STEPS):
        mujoco.mj_step(model, data)
    return STEP_RATE_STEPS / (time.perf_counter() - start)


def step_rates(paths: list[Path]) -> dict[str, float]:
    """Median steps/s of each model file, the rounds interleaved."""
    rounds: dict[str, list[float]] = {str(p): [] for p in paths}
    for _ in range(STEP_RATE_ROUNDS):
        for path in paths:
            rounds[str(path)].append(_step_once(path))
    return {name: statistics.median(values) for name, values in rounds.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("targets", nargs="*", help="robot names or spec paths (default: rosie_*)")
    parser.add_argument("--warm", type=int, default=3, help="warm rebuilds per robot (median)")
    parser.add_argument("--noop", type=int, default=5, help="no-op rebuilds per robot (median)")
    parser.add_argument("--jobs", type=int, default=None, help="passed to simkit build --jobs")
    parser.add_argument("--json", type=Path, default=None, help="also write the rows here")
    parser.add_argument(
        "--compare-step",
        type=int,
        default=0,
        metavar="N",
        help="also time N cold+warm rounds with and without --no-step (alternating) and "
        "print what the STEP assembly adds (median of the N rounds)",
    )
    parser.add_argument(
        "--step-parts", action="store_true", help="only time the parts of the STEP work"
    )
    parser.add_argument(
        "--step-rate", nargs="+", type=Path, metavar="MJCF", help="only time C MuJoCo stepping"
    )
    args = parser.parse_args()
    if args.step_rate:
        rates = step_rates(args.step_rate)
        base = next(iter(rates.values()))
        print("| model | steps/s (median) | ratio to the first |\n|---|---|---|")
        for name, rate in rates.items():
            print(f"| {name} | {rate:,.0f} | {rate / base:.2f} |")
        return
    targets = args.targets
    if args.step_parts:
        for target in targets:
            _step_parts(target)
        return
    if not targets:
        from simkit.kitio.resources import robot_names

        targets = [n for n in robot_names() if n.startswith("rosie_")]
    rows = [bench(t, args.warm, args.jobs, noop_runs=args.noop) for t in targets]
    print(
        f"cores: {len(os.sched_getaffinity(0))}, python {sys.version.split()[0]}, "
        f"load average {os.getloadavg()[0]:.2f}"
    )
    print(
        "| robot | cold s (CPU s) | warm s (CPU s) | no-op s (CPU s) | CoACD links | "
        "CoACD share | pieces (max/link) | max hull/solid | max visual-to-collision mm | "
        "visual tris | collision tris |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['robot']} | {r['cold_s']:.2f} ({r['cold_cpu_s']:.2f}) | "
            f"{r['warm_s']:.2f} ({r['warm_cpu_s']:.2f}) | "
            f"{r['noop_s']:.3f} ({r['noop_cpu_s']:.3f}) | {r['coacd_links']} | "
            f"{100 * r['coacd_share']:.0f} % | {r['pieces']} ({r['max_pieces_per_link']}) | "
            f"{r['max_hull_volume_ratio']:.3f} | {r['max_visual_to_collision_mm']:.2f} | "
            f"{r['visual_triangles']} | {r['collision_triangles']} |"
        )
    if args.compare_step:
        rows += _compare_step(targets, args.compare_step, args.warm, args.jobs)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")


def _step_parts(target: str) -> None:
    """CPU seconds of each part of the STEP work for one robot, in this process: the OCP
    import, the exact link solids, the whole emitter (solids + translate + write) and the
    check of a freshly built kit."""
    from simkit.pipeline import build, model_from_spec

    with tempfile.TemporaryDirectory(prefix="simkit-bench-") as tmp:
        kit = build(target, Path(tmp), check=False).kit_dir
        robot = model_from_spec(target)
        start = time.process_time()
        import OCP.OCP  # noqa: F401

        parts = {"OCP import": time.process_time() - start}
        from simkit.check.kit import Kit
        from simkit.check.step import check_step
        from simkit.derive import brep
        from simkit.emit import step

        for name, job in (
            ("link solids", lambda: [brep.link_shape(link) for link in robot.links]),
            ("STEP emitter", lambda: step.step_bytes(robot)),
            ("STEP check", lambda: check_step(Kit.open(kit))),
        ):
            start = time.process_time()
            job()
            parts[name] = time.process_time() - start
    print(f"{target}: " + ", ".join(f"{k} {v:.2f} s" for k, v in parts.items()) + " (CPU)")


def _compare_step(targets: list[str], rounds: int, warm: int, jobs: int | None) -> list[dict]:
    """Cold and warm build time with the STEP assembly and with `--no-step`, alternating the
    two in each round so that load on the machine hits both alike; medians over rounds. CPU
    seconds (the build process and any workers) depend far less on other load than wall time."""
    out = []
    print(
        "\n| robot | cold s (STEP / --no-step) | STEP adds cold s | cold CPU s added | "
        "warm s (STEP / --no-step) | STEP adds warm s | warm CPU s added |"
    )
    print("|---|---|---|---|---|---|---|")
    for target in targets:
        runs: dict[str, list[dict]] = {"step": [], "no_step": []}
        for _ in range(rounds):
            runs["step"].append(bench(target, warm, jobs))
            runs["no_step"].append(bench(target, warm, jobs, ("--no-step",)))
        med = {
            k: {
                m: statistics.median(r[m] for r in v)
                for m in ("cold_s", "warm_s", "cold_cpu_s", "warm_cpu_s")
            }
            for k, v in runs.items()
        }
        row = {
            "robot": runs["step"][0]["robot"],
            "rounds": rounds,
            "step": med["step"],
            "no_step": med["no_step"],
            "step_adds_cold_s": med["step"]["cold_s"] - med["no_step"]["cold_s"],
            "step_adds_warm_s": med["step"]["warm_s"] - med["no_step"]["warm_s"],
            "step_adds_cold_cpu_s": med["step"]["cold_cpu_s"] - med["no_step"]["cold_cpu_s"],
            "step_adds_warm_cpu_s": med["step"]["warm_cpu_s"] - med["no_step"]["warm_cpu_s"],
        }
        s, n = med["step"], med["no_step"]
        print(
            f"| {row['robot']} | {s['cold_s']:.2f} / {n['cold_s']:.2f} | "
            f"{row['step_adds_cold_s']:+.2f} | {row['step_adds_cold_cpu_s']:+.2f} | "
            f"{s['warm_s']:.2f} / {n['warm_s']:.2f} | {row['step_adds_warm_s']:+.2f} | "
            f"{row['step_adds_warm_cpu_s']:+.2f} |"
        )
        out.append(row)
    return out


if __name__ == "__main__":
    main()
