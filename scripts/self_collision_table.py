"""Self-collision of built kits as a Markdown table (docs/self-collision.md).

    PYTHONPATH=src python scripts/self_collision_table.py KITS_DIR [KITS_DIR ...]

For every `*_description` kit under each folder: MuJoCo on the kit's own MJCF (its collision
geometry, contact excludes and parent-child filter; simkit.simulate.self_collision), each
joint's collision-free range about home (0.5 deg steps, penetration > 1 mm counts), the
clearance at home and the share of 10,000 seeded (seed 0) uniform random configurations
within the limits in self-contact. Reads only robot.json and the MJCF, so it also measures
kits built by older simkit versions.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path


def measure(kit: Path) -> tuple[dict, list[dict], dict]:
    """(robot.json, its movable joints, simulate.self_collision.summary) of one kit."""
    import mujoco

    from simkit.simulate.self_collision import summary

    doc = json.loads((kit / "robot.json").read_text(encoding="utf-8"))
    joints = [j for j in doc["joints"] if j["type"] != "fixed"]
    model = mujoco.MjModel.from_xml_path(str(kit / doc["files"]["mjcf"]))
    names = [j["name"] for j in joints]
    lower, upper = [j["lower"] for j in joints], [j["upper"] for j in joints]
    home = doc.get("home") or [0.0] * len(joints)
    return doc, joints, summary(model, names, lower, upper, home, seed=0)


def main(folders: list[str]) -> None:
    kits = [kit for folder in folders for kit in sorted(Path(folder).glob("*_description"))]
    results = [measure(kit) for kit in kits]
    print("| Robot | Random configurations in self-contact | Clearance at home |")
    print("|---|---|---|")
    for doc, _joints, s in results:
        clear = s["home_min_clearance_m"]
        pair = " / ".join(s["home_closest_pair"] or [])
        text = "-" if clear is None else f"{1000 * clear:.1f} mm ({pair})"
        print(f"| {doc['name']} | {100 * s['random_contact_fraction']:.1f} % | {text} |")
    print()
    print("| Robot | Joint | Limits (deg) | Collision-free range about home (deg) |")
    print("|---|---|---|---|")
    for doc, joints, s in results:
        for joint, r in zip(joints, s["free_ranges"], strict=True):
            limit = f"{math.degrees(joint['lower']):.1f} .. {math.degrees(joint['upper']):.1f}"
            free = f"{math.degrees(r['lower']):.1f} .. {math.degrees(r['upper']):.1f}"
            mark = " **collides inside the limits**" if r["limited_by_collision"] else ""
            print(f"| {doc['name']} | {joint['name']} | {limit} | {free}{mark} |")


if __name__ == "__main__":
    main(sys.argv[1:])
