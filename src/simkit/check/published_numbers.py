"""Checks of robot.json against itself and the published numbers (0.1 mm, 0.01 kg)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from simkit.check.findings import Finding, compare
from simkit.check.kit import Kit
from simkit.kitio.fmt import SIGNIFICANT_DIGITS
from simkit.spec.load import SourceDoc

LENGTH_TOL = 1e-4  # m: the published numbers must match to 0.1 mm
MASS_TOL = 0.01  # kg
FK_REF_TOL = 1e-9  # m and rotation-matrix entries, on top of the file's own rounding


def rounding_bound(kit: Kit, q) -> tuple[float, float]:
    """Bounds on how far the tool can move (m, rotation-matrix entries) because robot.json
    writes every number with `fmt.SIGNIFICANT_DIGITS` digits: the FK reference is computed
    from the spec's exact numbers, the check's FK from the written ones. Each written angle,
    length or joint value is off by at most `eps` times its size, an axis component likewise
    (a turn of at most sqrt(3) eps |q|). An origin angle near pi alone is off by 5e-10 rad,
    so a chain of such origins (one arm's URDF in the corpus) exceeds a fixed 1e-9 with exact
    numbers."""
    eps = 0.5 * 10.0 ** (1 - SIGNIFICANT_DIGITS)
    values = dict(zip([j["name"] for j in kit.joints], q, strict=True))
    by_child = {j["child"]: j for j in kit.joints + kit.doc["fixed_joints"]}
    frame = kit.doc["frames"].get(kit.doc["tool_frame"]) or {}
    node = kit.doc["tool_frame"]
    angle = length = reach = 0.0
    if node not in by_child and "parent" in frame:
        angle += float(np.abs(frame["rpy"]).sum())
        length += float(np.linalg.norm(frame["xyz"]))
        node = frame["parent"]
    while node != kit.base_frame:
        joint = by_child[node]
        value = abs(values.get(joint["name"], 0.0))
        angle += float(np.abs(joint["origin_rpy"]).sum())
        if joint.get("type") == "prismatic":  # fixed joints carry no type
            length += value * (1 + np.sqrt(3))
        else:
            angle += value * (1 + np.sqrt(3))
        length += float(np.linalg.norm(joint["origin_xyz"]))
        node = joint["parent"]
    reach = length
    return eps * (length + angle * reach), eps * angle


def check_published(kit: Kit) -> list[Finding]:
    """robot.json's FK reference poses against its own joints, and each published figure
    against the model (`published_values`)."""
    doc = kit.doc
    findings: list[Finding] = []
    for ref in doc.get("fk_reference", []):
        if doc.get("tool_frame") in ref:
            actual = kit.fk(ref["q"])
            expected = ref[doc["tool_frame"]]
            length, angle = rounding_bound(kit, ref["q"])
            findings.append(
                compare(
                    f"fk_reference.{ref['pose']}",
                    "tool pose from robot.json joints",
                    expected["xyz"],
                    actual[:3, 3],
                    FK_REF_TOL + length,
                    "m",
                )
            )
            findings.append(
                compare(
                    f"fk_reference.{ref['pose']}.rotation",
                    "tool rotation",
                    expected["rotation"],
                    actual[:3, :3],
                    FK_REF_TOL + angle,
                    "",
                )
            )
    findings += [
        compare(p.check, p.detail, p.published, p.model, p.tolerance, p.unit)
        for p in published_values(kit)
    ]
    return findings


@dataclass(frozen=True)
class Published:
    """One published figure beside the model's: `field` is its key under the spec's
    `published:` block, `published` the spec's value, `model` the kit's (robot.json)."""

    field: str
    check: str
    detail: str
    published: Any
    model: Any
    tolerance: float
    unit: str

    @property
    def ok(self) -> bool:
        return compare("", "", self.published, self.model, self.tolerance, self.unit).ok


def published_values(kit: Kit) -> list[Published]:
    """Every published figure robot.json carries, with the model's value computed from
    robot.json alone: the one computation behind `check_published` and
    `simkit build --accept-published`."""
    doc, pub = kit.doc, kit.doc.get("published", {})
    out: list[Published] = []

    def add(field: str, suffix: str, what: str, model: Any, tolerance: float, unit: str):
        check = f"published.{field}{suffix}"
        out.append(Published(field, check, what, pub[field], model, tolerance, unit))

    if "mass" in pub:
        total = sum(link["mass"] for link in doc["links"])
        add("mass", "", "sum of link masses", total, MASS_TOL, "kg")
    if "tool0_home" in pub and doc.get("home") is not None:
        tool = [float(v) for v in kit.fk(doc["home"])[:3, 3]]
        add("tool0_home", "", "tool0 at home in base_link", tool, LENGTH_TOL, "m")
    if "base_link_height" in pub:
        height = doc["frames"].get(doc["base_frame"], {}).get("height")
        what = f"{doc['base_frame']} above the root"
        add("base_link_height", "", what, np.nan if height is None else height, LENGTH_TOL, "m")
    if "wrist_centre_reach" in pub:
        geometric = (doc.get("reach") or {}).get("geometric") or {}
        what = "wrist centre from the J1 axis, stretched"
        add("wrist_centre_reach", "", what, geometric.get("wrist", np.nan), LENGTH_TOL, "m")
        stretched = doc["poses"].get("stretched")
        if stretched is not None and doc.get("wrist_centre"):
            centre = kit.fk(stretched, doc["wrist_centre"])[:3, 3]
            what = "wrist centre from robot.json FK, stretched"
            reach = float(np.hypot(centre[0], centre[1]))
            add("wrist_centre_reach", ".fk", what, reach, LENGTH_TOL, "m")
    return out


def explain(finding: Finding, spec: SourceDoc) -> str | None:
    """A failed `published.*` finding as what it means and what to do, at the spec's line:
    the spec publishes a value the model no longer gives. None for any other finding."""
    parts = finding.check.split(".")
    if finding.ok or parts[0] != "published" or len(parts) < 2:
        return None
    field = parts[1]
    line = spec.lines.get(("published", field))
    where = f"{spec.file}:{line}" if line is not None else spec.file
    unit = f" {finding.unit}" if finding.unit else ""
    return (
        f"{where}: published.{field}: the spec publishes {finding.expected}{unit}, the model "
        f"gives {finding.actual}{unit} ({finding.detail.split(' (worst')[0]}; tolerance "
        f"{finding.tolerance}{unit}): correct that line, or build again with "
        f"--accept-published to write the model's value there"
    )
