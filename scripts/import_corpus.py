"""Import and build every URDF of example-robot-data (issue 15); print and save the table.

    python scripts/import_corpus.py [--only SUBSTR ...] [--timeout S] [--hull] [--out DIR]
    python scripts/import_corpus.py --rerun --only SUBSTR ...   # after a fix: replace rows

Each robot: `simkit import` (with `--hull` if asked), a cold build with an empty cache,
then a warm build with the same cache. Writes docs/import-corpus.md. Runs one build at a time.
"""

from __future__ import annotations

import argparse
import json
import re
import resource
import shutil
import site
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: robot folders whose root link moves freely (legged, humanoid, flying): --floating-base
FLOATING = (
    "a1_", "alexander_", "anymal", "b1_", "bolt_", "borinot", "centauro", "g1_",
    "go1_", "go2_", "hector", "hextilt", "human_", "hyq", "icub", "iris", "laikago",
    "quadruped", "romeo", "simple_humanoid", "solo_", "talos_data",
)  # fmt: skip
#: URDFs in those folders that are fixed-base all the same: a single arm (Talos's left arm);
#: Alex (alex_description) is an upper body without legs, mounted on a stand, so not listed
FIXED = ("talos_left_arm.urdf",)


def floating(rel: Path) -> bool:
    """Whether the corpus URDF at `rel` (relative to the corpus root) has a floating base."""
    return rel.parts[0].startswith(FLOATING) and rel.name not in FIXED


BIG = ("talos_full_v2.urdf", "g1_29dof_rev_1_0", "tiago.urdf", "pr2.urdf")


def corpus() -> Path:
    for base in site.getsitepackages():
        path = Path(base) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if path.is_dir():
            return path
    sys.exit("example-robot-data is not installed (pip install example-robot-data==6.0.0)")


def _cpu() -> float:
    """CPU seconds (user + system) used by finished child processes so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run(args: list[str], timeout: float) -> tuple[int, str, tuple[float, float]]:
    """Exit code, last line of output, and (wall s, CPU s) of one simkit command."""
    start, cpu = time.perf_counter(), _cpu()
    try:
        done = subprocess.run(
            [sys.executable, "-m", "simkit.cli", *args],
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return 124, f"timed out after {timeout:.0f} s", (time.perf_counter() - start, 0.0)
    text = (done.stderr.strip().splitlines() or [""])[-1] if done.returncode else done.stdout
    return done.returncode, text, (time.perf_counter() - start, _cpu() - cpu)


def _first_failure(message: str) -> str:
    found = re.search(r"FAIL ([\w.]+)", message)
    return found.group(1) if found else message[:90]


def one(urdf: Path, root: Path, work: Path, timeout: float, hull: bool) -> dict:
    rel = urdf.relative_to(root)
    name = re.sub(r"[^a-z0-9_]+", "_", f"{rel.parts[0]}_{urdf.stem}".lower())
    name = name.replace("_description", "")
    row = {"robot": str(rel), "import": "", "build": "", "failing": "", "cold": None,
           "warm": None, "links": None, "coacd": None}  # fmt: skip
    args = ["import", str(urdf), "--name", name, "--out", str(work / "specs" / name), "-q"]
    args += ["--floating-base"] if floating(rel) else []
    args += ["--hull"] if hull else []
    rc, text, _s = _run(args, timeout)
    if rc:
        message = text.removeprefix("simkit: error: ").replace(str(root) + "/", "")
        row["import"] = "error: " + message[:160]
        return row
    row["import"] = "ok"
    spec = work / "specs" / name / f"{name}.yaml"
    cache = work / "cache" / name
    kits = work / "kits"
    build = ["build", str(spec), "--out", str(kits), "-q", "--cache-dir", str(cache)]
    shutil.rmtree(cache, ignore_errors=True)  # cold means cold: no entries from earlier runs
    rc, text, row["cold"] = _run(build, timeout)
    if rc:
        row["build"] = "fail"
        row["failing"] = _first_failure(text)
        return row
    rc, text, row["warm"] = _run(build, timeout)
    row["build"] = "ok" if rc == 0 else "fail (warm)"
    doc = json.loads((kits / f"{name}_description" / "robot.json").read_text())
    row["links"] = len(doc["links"])
    methods = [g.get("collision", {}).get("method") for g in doc["geometry"]["links"]]
    row["coacd"] = sum(m == "coacd" for m in methods) / max(len(methods), 1)
    return row


def table(rows: list[dict]) -> str:
    head = (
        "| robot | import | build | first failing check | cold s (CPU s) | warm s (CPU s) "
        "| links | CoACD |"
    )
    lines = [head, "|---|---|---|---|---:|---:|---:|---:|"]
    for r in rows:
        num = [f"{r[k][0]:.1f} ({r[k][1]:.1f})" if r[k] else "" for k in ("cold", "warm")]
        share = f"{100 * r['coacd']:.0f} %" if r["coacd"] is not None else ""
        lines.append(
            f"| {r['robot']} | {r['import']} | {r['build']} | {r['failing']} | {num[0]} | "
            f"{num[1]} | {r['links'] or ''} | {share} |"
        )
    passed = sum(r["build"] == "ok" for r in rows)
    lines.append("")
    lines.append(
        f"{passed} of {len(rows)} pass `simkit check` ({100 * passed / max(len(rows), 1):.1f} %)."
    )
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", default=[], help="substrings of robot paths")
    parser.add_argument("--timeout", type=float, default=600.0, help="s per import or build")
    parser.add_argument("--hull", action="store_true", help="import with --hull")
    parser.add_argument("--out", type=Path, default=Path("/tmp/simkit-corpus"))
    parser.add_argument("--md", type=Path, default=REPO / "docs" / "import-corpus.md")
    parser.add_argument(
        "--rerun",
        action="store_true",
        help="with --only: rerun these robots and replace their rows in OUT/rows.json (the "
        "last full run), then rewrite the table",
    )
    args = parser.parse_args()
    root = corpus()
    # the largest robots first (issue 15's performance targets), then the rest by path
    urdfs = sorted(root.rglob("*.urdf"), key=lambda p: (not p.name.startswith(BIG), str(p)))
    if args.only:
        urdfs = [p for p in urdfs if any(s in str(p.relative_to(root)) for s in args.only)]
    saved = args.out / "rows.json"
    earlier = json.loads(saved.read_text()) if args.rerun and saved.is_file() else []
    rows = []
    for urdf in urdfs:
        row = one(urdf, root, args.out, args.timeout, args.hull)
        rows.append(row)
        print(f"{row['robot']}: import {row['import']}, build {row['build']} {row['failing']} "
              f"cold {row['cold']} warm {row['warm']}", flush=True)  # fmt: skip
        if not args.rerun:
            _save(args.md, rows, len(urdfs))
            saved.write_text(json.dumps(rows, indent=1))
    if args.rerun:  # the rows of the last full run, these robots replaced
        fresh = {r["robot"]: r for r in rows}
        rows = [fresh.get(r["robot"], r) for r in earlier]
        saved.write_text(json.dumps(rows, indent=1))
        _save(args.md, rows, len(rows), rerun=sorted(fresh))
    print(table(rows))


def _save(md: Path, rows: list[dict], total: int, rerun: list[str] = ()) -> None:
    """Write the table so far (a long run leaves a partial table if stopped)."""
    done = "" if len(rows) == total else f" (partial: {len(rows)} of {total} URDFs run)"
    if rerun:
        done = (
            " (rows of the last full run, saved in OUT/rows.json, with these robots rerun "
            f"after fixes: {', '.join(rerun)})"
        )
    md.write_text(
        "# Import corpus: example-robot-data 6.0.0\n\n"
        "Made by `python scripts/import_corpus.py "
        + " ".join(sys.argv[1:])
        + "`"
        + done
        + ": import as `simkit import` does by default (URDF collision kept as convex pieces, "
        "CoACD "
        "above ten), `--hull` if given; cold = empty cache, warm = second build "
        "with that cache; wall seconds with CPU seconds (user + system, all processes) in "
        "brackets, on 2 cores shared with other work.\n\n" + table(rows)
    )


if __name__ == "__main__":
    main()
