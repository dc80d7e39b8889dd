"""The free-fall check: simulate the written MJCF and URDF again and hold every pair of the
three simulations (MJCF, URDF, independent integration from validation/freefall.csv) to the
spec's joint-angle RMS bound (report 002_e760a3794accbbd5.txt, section 4 step 4).

Active only when robot.json has `validation.freefall`."""

from __future__ import annotations

import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.simulate import freefall

#: rad: the written files must reproduce the trajectories recorded at build time this closely
#: (the CSV keeps 10 significant digits; MuJoCo is deterministic on one machine).
REPRODUCE_TOL = 1e-6


def _read_csv(kit: Kit, rel: str) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    lines = kit.path(rel).read_text(encoding="utf-8").splitlines()
    header = lines[0].split(",")
    table = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    return table[:, 0], {name: table[:, i] for i, name in enumerate(header) if i}


def check_freefall(kit: Kit) -> list[Finding]:
    record = kit.doc.get("validation", {}).get("freefall")
    if record is None:
        return []
    files = record["files"]
    missing = [p for p in files.values() if not kit.path(p).is_file()]
    if missing:
        return [require("freefall.files", False, f"missing: {', '.join(missing)}")]
    findings = [require("freefall.files", True, "validation CSV and plot are in the kit")]
    times, columns = _read_csv(kit, files["csv"])
    joints, tol = record["joints"], record["tolerance_rms"]
    expected_t = freefall.sample_times(record["duration"])
    findings.append(compare("freefall.samples", "CSV sample times", expected_t, times, 1e-9, "s"))
    if times.shape != expected_t.shape:
        return findings
    armature = [(j["name"], j["armature"]) for j in kit.joints]
    runs, _, _ = freefall.mujoco_runs(
        kit.path(kit.mjcf), kit.path(kit.urdf), armature, record["q0"], record["duration"]
    )
    for run in freefall.RUNS:
        sides = {
            "independent": np.column_stack([columns[f"{run}.independent.{j}"] for j in joints]),
            **runs[run],
        }
        for side in ("mjcf", "urdf"):
            recorded = np.column_stack([columns[f"{run}.{side}.{j}"] for j in joints])
            findings.append(
                compare(
                    f"freefall.{run}.{side}.reproduce",
                    f"{side.upper()} free fall ({run}) vs the recorded trajectory",
                    recorded,
                    sides[side],
                    REPRODUCE_TOL,
                    "rad",
                )
            )
        for a, b in freefall.PAIRS:
            value = freefall.rms(sides[a], sides[b])
            findings.append(
                compare(
                    f"freefall.{run}.{a}_vs_{b}",
                    f"joint-angle RMS difference, {a} vs {b}, {record['duration']:g} s free fall "
                    f"from '{record['pose']}' ({run} run)",
                    0.0,
                    value,
                    tol,
                    "rad",
                )
            )
    return findings
