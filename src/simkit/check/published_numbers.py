"""Checks of robot.json against itself and the published numbers (0.1 mm, 0.01 kg)."""

from __future__ import annotations

import numpy as np

from simkit.check.findings import Finding, compare
from simkit.check.kit import Kit

LENGTH_TOL = 1e-4  # m: the published numbers must match to 0.1 mm
MASS_TOL = 0.01  # kg


def check_published(kit: Kit) -> list[Finding]:
    doc, pub = kit.doc, kit.doc.get("published", {})
    findings: list[Finding] = []
    for ref in doc.get("fk_reference", []):
        if doc.get("tool_frame") in ref:
            actual = kit.fk(ref["q"])
            expected = ref[doc["tool_frame"]]
            findings.append(
                compare(
                    f"fk_reference.{ref['pose']}",
                    "tool pose from robot.json joints",
                    expected["xyz"],
                    actual[:3, 3],
                    1e-9,
                    "m",
                )
            )
            findings.append(
                compare(
                    f"fk_reference.{ref['pose']}.rotation",
                    "tool rotation",
                    expected["rotation"],
                    actual[:3, :3],
                    1e-9,
                    "",
                )
            )
    if "mass" in pub:
        total = sum(link["mass"] for link in doc["links"])
        findings.append(
            compare("published.mass", "sum of link masses", pub["mass"], total, MASS_TOL, "kg")
        )
    if "tool0_home" in pub and doc.get("home") is not None:
        findings.append(
            compare(
                "published.tool0_home",
                "tool0 at home in base_link",
                pub["tool0_home"],
                kit.fk(doc["home"])[:3, 3],
                LENGTH_TOL,
                "m",
            )
        )
    if "base_link_height" in pub:
        height = doc["frames"].get(doc["base_frame"], {}).get("height")
        findings.append(
            compare(
                "published.base_link_height",
                f"{doc['base_frame']} above the root",
                pub["base_link_height"],
                height if height is not None else np.nan,
                LENGTH_TOL,
                "m",
            )
        )
    geometric = (doc.get("reach") or {}).get("geometric") or {}
    if "wrist_centre_reach" in pub:
        findings.append(
            compare(
                "published.wrist_centre_reach",
                "wrist centre from the J1 axis, stretched",
                pub["wrist_centre_reach"],
                geometric.get("wrist", np.nan),
                LENGTH_TOL,
                "m",
            )
        )
        stretched = doc["poses"].get("stretched")
        if stretched is not None and doc.get("wrist_centre"):
            centre = kit.fk(stretched, doc["wrist_centre"])[:3, 3]
            findings.append(
                compare(
                    "published.wrist_centre_reach.fk",
                    "wrist centre from robot.json FK, stretched",
                    pub["wrist_centre_reach"],
                    float(np.hypot(centre[0], centre[1])),
                    LENGTH_TOL,
                    "m",
                )
            )
    return findings
