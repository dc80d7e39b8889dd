"""Import robots, build their kits and run NVIDIA's SimReady robot validation on their USD.

    python scripts/usd_simready.py ROBOT_FILE [ROBOT_FILE ...] [--out DIR] [--md FILE]

Each URDF or MJCF file: `simkit import FILE --out DIR/specs/N` with no other flag, `simkit build`
(every kit check), then the requirement set of tests/test_usd_simready.py (the Robot-Body
profile's newest version, its neutral features and FET_031/FET_033, and the Isaac tier's robot
features) on the Isaac asset `usd/NAME/NAME.usda` and on the entry point `usd/NAME.usda`,
through tests/simready_check.py. Prints one Markdown row per robot: the base, links and joints,
the kit checks, the asset's failures and errors, and the entry point's beyond RC.003 (its
folder is `usd/`, docs/usd.md); every failure and error follows the table, with rule and prim.
No robot is named here: the files come from the command line."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))

from simready_check import ISAAC_TIER, profile_features, requirement_ids, validate  # noqa: E402

ENTRY_ONLY = "com.nvidia.simready.RC.003"


def _simkit(*args: str) -> subprocess.CompletedProcess:
    """`simkit ARGS` from this checkout's src/ (before any installed simkit)."""
    paths = [str(REPO / "src"), os.environ.get("PYTHONPATH", "")]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in paths if p)}
    return subprocess.run(
        [sys.executable, "-m", "simkit.cli", *args],
        capture_output=True,
        text=True,
        check=False,
        env=env,
    )


def one(path: Path, out: Path, wanted: list[str]) -> tuple[dict, list[str]]:
    """(table row, problem lines) of one robot file."""
    row = {"file": path.name, "base": "", "links": "", "joints": "", "checks": "", "asset": ""}
    start = time.monotonic()
    done = _simkit("import", str(path), "--out", str(out / "spec"), "-q")
    specs = sorted((out / "spec").glob("*.yaml"))
    if done.returncode != 0 or not specs:
        row["checks"] = "import refused: " + (done.stderr.strip().splitlines() or ["?"])[-1]
        return row, []
    built = _simkit("build", str(specs[0]), "--out", str(out / "kit"), "-q")
    kits = sorted((out / "kit").glob("*_description"))
    if not kits:
        row["checks"] = "build failed: " + (built.stderr.strip().splitlines() or ["?"])[-1]
        return row, []
    doc = json.loads((kits[0] / "robot.json").read_text())
    name = doc["name"]
    row["base"] = "floating" if doc.get("floating_base") else "fixed"
    row["links"] = str(len(doc["links"]))
    row["joints"] = str(len(doc["joints"]))  # robot.json lists movable joints only
    row["checks"] = "pass" if built.returncode == 0 else "FAIL"
    asset = validate(kits[0] / "usd" / name / f"{name}.usda", wanted)
    entry = validate(kits[0] / "usd" / f"{name}.usda", wanted)
    extra = [p for p in entry if p.requirement != ENTRY_ONLY]
    count = lambda problems, kind: sum(p.severity == kind for p in problems)  # noqa: E731
    row["asset"] = f"{count(asset, 'FAILURE')} / {count(asset, 'ERROR')}"
    row["entry"] = f"{count(extra, 'FAILURE')} / {count(extra, 'ERROR')}"
    row["seconds"] = f"{time.monotonic() - start:.1f}"
    lines = [f"{name} asset: {p.line()}" for p in asset]
    return row, lines + [f"{name} entry: {p.line()}" for p in extra]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="+", type=Path)
    parser.add_argument("--out", type=Path, default=Path("/tmp/simkit-usd-simready"))
    args = parser.parse_args()
    _newest, features = profile_features()
    wanted = requirement_ids([*features, *ISAAC_TIER])
    cols = ("file", "base", "links", "joints", "checks", "asset", "entry", "seconds")
    print(
        "| robot file | base | links | movable joints | kit checks | Isaac asset failures / "
        "errors | entry point failures / errors beyond RC.003 | import + build + validate s |"
    )
    print("|" + "---|" * len(cols))
    problems: list[str] = []
    for i, path in enumerate(args.files):
        row, lines = one(path.resolve(), args.out / f"{i:02d}", wanted)
        print("| " + " | ".join(row.get(c, "") for c in cols) + " |", flush=True)
        problems += lines
    for line in problems:
        print(line)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
