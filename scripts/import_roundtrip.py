"""Round trip (issue 15): build a seed robot, `simkit import` its kit's URDF, build that, and
`simkit diff` the two kits. Kinematics, limits, masses, CoM and inertia must not change;
what a URDF cannot carry (drives, MuJoCo-only settings, published ratings) is named.

    python scripts/import_roundtrip.py [NAME ...] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

SEEDS = ("rosie_600", "rosie_1000", "rosie_1400", "asimov", "ecn_2r")
#: robot.json joint / link fields a URDF carries: they must survive the round trip
KEPT_JOINT = ("type", "parent", "child", "origin_xyz", "origin_rpy", "axis", "lower", "upper",
              "max_velocity", "effort_peak", "damping", "friction")  # fmt: skip
KEPT_LINK = ("mass", "com", "inertia")


def _simkit(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "simkit.cli", *args], capture_output=True, text=True
    )


def _close(a, b, tol: float = 1e-9) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k], tol) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y, tol) for x, y in zip(a, b, strict=True))
    if isinstance(a, float | int) and isinstance(b, float | int):
        return abs(a - b) <= tol * max(1.0, abs(a))
    return a == b


def compare(old: dict, new: dict) -> list[str]:
    """Fields a URDF carries that differ between the two robot.json documents."""
    problems = []
    joints = {j["name"]: j for j in new["joints"]}
    for joint in old["joints"]:
        if joint["type"] == "floating":  # not in a URDF: the importer adds its own
            continue
        other = joints.get(joint["name"])
        for key in KEPT_JOINT if other else ():
            if not _close(joint.get(key), other.get(key)):
                problems.append(
                    f"joint {joint['name']}.{key}: {joint.get(key)} -> {other.get(key)}"
                )
        if other is None:
            problems.append(f"joint {joint['name']} missing")
    links = {link["name"]: link for link in new["links"]}
    for link in old["links"]:
        other = links.get(link["name"])
        for key in KEPT_LINK if other else ():
            if not _close(link.get(key), other.get(key), 1e-7):
                problems.append(f"link {link['name']}.{key}: {link.get(key)} -> {other.get(key)}")
        if other is None:
            problems.append(f"link {link['name']} missing")
    return problems


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", default=list(SEEDS))
    parser.add_argument("--out", type=Path, default=Path("/tmp/simkit-roundtrip"))
    args = parser.parse_args()
    failed = False
    for name in args.names:
        orig, again = args.out / "orig", args.out / "again"
        built = _simkit("build", name, "--out", str(orig), "-q")
        if built.returncode:
            sys.exit(f"{name}: build failed: {built.stderr.strip()}")
        kit = orig / f"{name}_description"
        doc = json.loads((kit / "robot.json").read_text())
        flags = ["--floating-base"] if doc.get("floating_base") else []
        spec_dir = args.out / "specs" / name
        step = _simkit("import", str(kit / "urdf" / f"{name}.urdf"), "--name", name,
                       "--out", str(spec_dir), "-q", *flags)  # fmt: skip
        if step.returncode:
            sys.exit(f"{name}: import failed: {step.stderr.strip()}")
        step = _simkit("build", str(spec_dir / f"{name}.yaml"), "--out", str(again), "-q")
        if step.returncode:
            print(f"{name}: build of the import failed: {step.stderr.strip()[:300]}")
            failed = True
            continue
        new = json.loads((again / f"{name}_description" / "robot.json").read_text())
        problems = compare(doc, new)
        report = _simkit("diff", str(kit), str(again / f"{name}_description")).stdout
        (args.out / f"{name}.diff.md").write_text(report)
        lost = [line[2:] for line in report.splitlines() if line.startswith("- `")]
        print(f"{name}: {'kept' if not problems else 'CHANGED'} kinematics, limits, masses, CoM, "
              f"inertia; diff names: {', '.join(lost[:12])}")  # fmt: skip
        for problem in problems:
            print(f"  {problem}")
        failed |= bool(problems)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
