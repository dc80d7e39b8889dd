"""Long-run spec fuzzer (issue 13): mutate a small spec many times and build each mutation.

Every mutation is validated in-process first (`validate.load_spec`, the code `simkit build`
runs first); one that validates is built with the real CLI in a subprocess
(`python -m simkit.cli build SPEC --out DIR`, 60 s of CPU per process, 600 s wall
backstop), and an exit-0 kit is checked with `simkit check`. Counted: refusals (one
line), tracebacks or other exceptions, runs over 60 s, files written outside --out, and
exit-0 kits that `simkit check` rejects.

    python scripts/fuzz_specs.py --count 10000 --seed 1 --work /tmp/fuzz [--max-seconds N]
    python scripts/fuzz_specs.py --count 10000 --seed 2 --validate-only   # no builds
    python scripts/fuzz_specs.py --count 10000 --seed 1 --ray [--resume]  # shards on Ray

Each spec i is mutated from its own seed (SEED:i), so shards run anywhere in any order, a
stopped run continues with --resume (WORK/results.jsonl), and equal seeds give equal tables.

Mutations (seeded, so a run is reproducible): perturb a number (mostly still valid, so it
builds), set a field to a hostile value, delete or add a key, copy a list item, or edit the
raw YAML text (insert/cut characters and YAML syntax such as anchors, tags, merge keys, NUL).
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import random
import resource
import shutil
import signal
import subprocess
import sys
import time
import traceback
from pathlib import Path

import yaml

REPO = Path(__file__).resolve().parents[1]
HOSTILE = [
    "",
    "../../x",
    'a"""b',
    "a\nb",
    "x" * 300,
    "tool0_joint",
    "link_1_collision_00",
    "LINK_1",
    "joint-1",
    "on",
    "null",
    "<x/>",
    None,
    True,
    -1,
    0,
    1e-12,
    1e12,
    1e308,
    36000,
    [],
    {},
    [1, 2, 3],
    {"a": 1},
]
SNIPPETS = ["<<: *a", "&a ", "*a", "!!python/object:os.system ", "!foo ", "\x00", "[" * 60]
SNIPPETS += ["{", "- ", ": ", "\t", "'", '"', "---\n", "~", "? ", "1e999", "\n  - ", "-"]


def _paths(value: object, prefix: tuple = ()) -> list[tuple]:
    out = [prefix]
    if isinstance(value, dict):
        for key, item in value.items():
            out += _paths(item, (*prefix, key))
    elif isinstance(value, list):
        for i, item in enumerate(value):
            out += _paths(item, (*prefix, i))
    return out


def mutate(text: str, data: dict, rng: random.Random) -> tuple[str, str]:
    """(mutated YAML text, what was done)."""
    kind = rng.choices(["perturb", "structure", "raw"], weights=[4, 3, 3])[0]
    if kind == "raw":
        for _ in range(rng.randint(1, 3)):
            at = rng.randint(0, len(text))
            insert = rng.choice(SNIPPETS) if rng.random() < 0.7 else chr(rng.randint(32, 126))
            text = text[:at] + insert + text[at + rng.randint(0, 20) :]
        return text, "raw"
    out = copy.deepcopy(data)
    paths = [p for p in _paths(out) if p]
    if kind == "perturb":
        numeric = [p for p in paths if _get(out, p).__class__ in (int, float)]
        path = rng.choice(numeric)
        value = _get(out, path)
        factor = rng.choice([0.5, 0.9, 1.1, 2.0, -1.0, 10.0, 0.0])
        new = value * factor + (rng.random() * 0.01 if factor == 0.0 else 0.0)
        _set(out, path, type(value)(new) if isinstance(value, int) else new)
        return yaml.safe_dump(out, allow_unicode=True), f"perturb {path}"
    path = rng.choice(paths)
    action = rng.choice(["set", "delete", "add", "copy"])
    parent = _get(out, path[:-1])
    if action == "delete":
        del parent[path[-1]]
    elif action == "add" and isinstance(parent, dict):
        parent[f"{path[-1]}_x"] = rng.choice(HOSTILE)
    elif action == "copy" and isinstance(parent, list):
        parent.append(copy.deepcopy(parent[path[-1]]))
    else:
        parent[path[-1]] = copy.deepcopy(rng.choice(HOSTILE))
    return yaml.safe_dump(out, allow_unicode=True), f"{action} {path}"


def _get(data, path):
    for part in path:
        data = data[part]
    return data


def _set(data, path, value):
    _get(data, path[:-1])[path[-1]] = value


def _listing(root: Path, skip: Path) -> set[str]:
    return {str(p) for p in root.rglob("*") if skip not in p.parents and p != skip}


def _one_line(stderr: str) -> bool:
    lines = [
        line
        for line in stderr.splitlines()
        if line.strip() and not line.startswith(("[", "simkit: warning:"))
    ]
    # one error, its further lines (a spec's other problems, each failed check) indented or
    # FILE:LINE: field: message, never a traceback
    return bool(lines) and lines[0].startswith("simkit: error: ") and "Traceback" not in stderr


#: "Over 60 s" means 60 s of CPU in any one process of the build (RLIMIT_CPU): on a shared
#: machine, or under `nice`, wall time also counts other people's work. A wall-clock
#: backstop catches a build that sleeps or waits instead.
CPU_LIMIT_S = 60
WALL_BACKSTOP_S = 600


def _limit_cpu() -> None:
    resource.setrlimit(resource.RLIMIT_CPU, (CPU_LIMIT_S, CPU_LIMIT_S + 1))


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run_one(
    spec: Path, out: Path, stats: dict, env: dict, build: bool = True, extra: tuple = ()
) -> str:
    """Validate, then build and check; returns the outcome name it counted."""
    from simkit.errors import SpecError
    from simkit.spec.validate import load_spec

    try:
        load_spec(spec)
    except SpecError as exc:
        lines = [line for line in str(exc).splitlines() if not line.startswith("(and ")]
        ok = all(line.startswith(str(spec)) for line in lines)  # one line per problem
        return "refused" if ok else "bad_refusal"
    except Exception:  # the fuzzer counts every other exception
        stats.setdefault("examples", []).append(traceback.format_exc(limit=3)[-600:])
        return "traceback"
    if not build:
        return "valid_not_built"
    cmd = [sys.executable, "-m", "simkit.cli", "build", str(spec), "--out", str(out), "-q"]
    cmd += list(extra)
    start, cpu = time.monotonic(), _children_cpu()
    try:
        proc = subprocess.run(
            cmd,
            capture_output=True,
            text=True,
            timeout=WALL_BACKSTOP_S,
            env=env,
            cwd=spec.parent,
            preexec_fn=_limit_cpu,
        )
    except subprocess.TimeoutExpired:
        return "over_60s"
    if proc.returncode in (-signal.SIGXCPU, -signal.SIGKILL):
        return "over_60s"
    stats["build_seconds"].append(time.monotonic() - start)
    stats["build_cpu_seconds"].append(_children_cpu() - cpu)
    if "Traceback" in proc.stderr + proc.stdout:
        stats.setdefault("examples", []).append(proc.stderr[-600:])
        return "traceback"
    if proc.returncode != 0:
        if not _one_line(proc.stderr):
            stats.setdefault("examples", []).append(proc.stderr[-600:])
            return "bad_refusal"
        stats.setdefault("build_refusals", []).append(proc.stderr.strip().splitlines()[-1][:300])
        return "build_refused"
    kits = [p for p in out.iterdir() if p.name.endswith("_description")]
    try:
        check = subprocess.run(
            [sys.executable, "-m", "simkit.cli", "check", str(kits[0])],
            capture_output=True,
            text=True,
            timeout=3 * WALL_BACKSTOP_S,  # a starved (niced) check is slow, not hung
            env=env,
            preexec_fn=_limit_cpu,
        )
    except subprocess.TimeoutExpired:
        return "over_60s"
    if check.returncode in (-signal.SIGXCPU, -signal.SIGKILL):
        return "over_60s"
    return "built_ok" if check.returncode == 0 else "check_rejects_exit0_kit"


def run_shard(
    spec_text: str, seed: int, indices: list[int], work: str, build: bool, extra: tuple = ()
) -> list:
    """Mutate and run the specs `indices` (each from its own seed, so any shard can run on
    any machine, in any order, and a stopped run resumes); one result dict per spec."""
    data = yaml.safe_load(spec_text)
    env = {**os.environ}
    if (REPO / "src").is_dir():  # this checkout's simkit first
        env["PYTHONPATH"] = os.pathsep.join(
            filter(None, [str(REPO / "src"), env.get("PYTHONPATH")])
        )
    root = Path(work) / f"shard-{indices[0]:05d}"  # private: shards run side by side
    root.mkdir(parents=True, exist_ok=True)
    results = []
    for i in indices:
        case = root / f"{i:05d}"
        shutil.rmtree(case, ignore_errors=True)
        case.mkdir()
        spec, out = case / "spec.yaml", case / "out"
        mutated, _what = mutate(spec_text, data, random.Random(f"{seed}:{i}"))
        spec.write_bytes(mutated.encode("utf-8", "surrogatepass"))
        stats: dict = {"build_seconds": [], "build_cpu_seconds": []}
        before = _listing(root, out)
        outcome = run_one(spec, out, stats, env, build=build, extra=extra)
        outside = _listing(root, out) != before
        if outcome in ("refused", "built_ok", "build_refused", "valid_not_built"):
            shutil.rmtree(case, ignore_errors=True)
        results.append({"index": i, "outcome": outcome, "outside": outside, **stats})
    return results


def _summary(args, results: dict[int, dict], begin: float) -> dict:
    """The figures so far, from every result of this work folder (resumed ones too), also
    written to WORK/summary.json. The same seeds give the same outcome table."""
    counts: dict[str, int] = {}
    seconds, cpu, examples, refusals = [], [], [], set()
    for _i, result in sorted(results.items()):
        counts[result["outcome"]] = counts.get(result["outcome"], 0) + 1
        if result["outside"]:
            counts["files_outside_out"] = counts.get("files_outside_out", 0) + 1
        seconds += result["build_seconds"]
        cpu += result["build_cpu_seconds"]
        examples += result.get("examples", [])
        refusals.update(result.get("build_refusals", []))
    summary = {
        "specs": len(results),
        "seed": args.seed,
        "outcomes": dict(sorted(counts.items())),
        "builds": len(seconds),
        "longest_build_s": round(max(seconds), 1) if seconds else 0.0,
        "longest_build_cpu_s": round(max(cpu, default=0.0), 1),
        "wall_s": round(time.monotonic() - begin, 1),
        "specs_per_minute": round(len(results) / max(time.monotonic() - begin, 1e-9) * 60, 1),
        "examples": examples[:5],
        "build_refusals": sorted(refusals)[:20],
    }
    (args.work / "summary.json").write_text(json.dumps(summary, indent=2))
    return summary


def _shards(todo: list[int], size: int) -> list[list[int]]:
    return [todo[k : k + size] for k in range(0, len(todo), size)]


def _run_serial(args, text: str, todo: list[int], record) -> None:
    for shard in _shards(todo, args.shard_size):
        if args.max_seconds and time.monotonic() - args.begin > args.max_seconds:
            break
        work = str(args.work / "cases")
        record(run_shard(text, args.seed, shard, work, not args.validate_only, args.extra))


def _run_ray(args, text: str, todo: list[int], record) -> None:
    """One Ray task per shard on the cluster in RAY_ADDRESS (else a local Ray); results are
    recorded as shards finish, so a stopped run resumes with --resume."""
    import ray

    if not ray.is_initialized():
        ray.init(address=os.environ.get("RAY_ADDRESS") or None, include_dashboard=False)
    task = ray.remote(num_cpus=1, max_retries=2)(run_shard)
    work = str(args.work / "cases")
    pending = [
        task.remote(text, args.seed, shard, work, not args.validate_only, args.extra)
        for shard in _shards(todo, args.shard_size)
    ]
    while pending:
        done, pending = ray.wait(pending, num_returns=1)
        record(ray.get(done[0]))
        if args.max_seconds and time.monotonic() - args.begin > args.max_seconds:
            for ref in pending:
                ray.cancel(ref, force=True)
            break


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--spec", type=Path, default=REPO / "tests/specs/planar_2r.yaml")
    parser.add_argument("--count", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--work", type=Path, default=Path("/tmp/simkit-fuzz"))
    parser.add_argument("--max-seconds", type=float, default=None, help="stop after this long")
    parser.add_argument(
        "--validate-only", action="store_true", help="no builds: validation outcomes only"
    )
    parser.add_argument("--ray", action="store_true", help="one Ray task per shard")
    parser.add_argument("--shard-size", type=int, default=10, help="specs per shard")
    parser.add_argument(
        "--resume", action="store_true", help="keep WORK's results; run only the specs left"
    )
    parser.add_argument("--start", type=int, default=0, help="first spec index (a shard range)")
    parser.add_argument("--no-step", action="store_true", help="build with --no-step")
    args = parser.parse_args()
    args.extra = ("--no-step",) if args.no_step else ()
    sys.path.insert(0, str(REPO / "src"))
    text = args.spec.read_text()
    results_file = args.work / "results.jsonl"
    if not args.resume:
        shutil.rmtree(args.work, ignore_errors=True)
    args.work.mkdir(parents=True, exist_ok=True)
    results: dict[int, dict] = {}
    if results_file.is_file():
        for line in results_file.read_text().splitlines():
            result = json.loads(line)
            results[result["index"]] = result
    todo = [i for i in range(args.start, args.count) if i not in results]
    args.begin = time.monotonic()

    def record(shard: list[dict]) -> None:
        with results_file.open("a") as stream:
            for result in shard:
                stream.write(json.dumps(result, sort_keys=True) + "\n")
                results[result["index"]] = result
        _summary(args, results, args.begin)

    (_run_ray if args.ray else _run_serial)(args, text, todo, record)
    summary = _summary(args, results, args.begin)
    print(json.dumps(summary, indent=2))
    bad = ("traceback", "over_60s", "files_outside_out", "check_rejects_exit0_kit", "bad_refusal")
    sys.exit(1 if any(summary["outcomes"].get(k) for k in bad) else 0)


if __name__ == "__main__":
    main()
