"""What index.json and the pages say about one kit, read from the built kit's files (robot.json,
package.xml, the file list) and its check findings: nothing is typed by hand.

Menagerie's registry and robot_descriptions list per robot its licence, category, DoF and
entry points; these facts are the same, derived from the model: a floating base with two or
more limbs of at least two joints is `legged`, one without is `floating`; a fixed base whose
moving joints form one chain is `arm`, one whose chain branches is `branched`.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from collections import defaultdict

from simkit.kitio import layout

#: a limb: a branch of the tree below the floating base with at least this many moving joints
LIMB_JOINTS = 2

#: check-name prefix -> the tool that loaded the output (the check modules in simkit/check);
#: the longest matching prefix wins, anything else is simkit's own reader
TOOLS = {
    "mjcf": "MuJoCo",
    "mass.mjcf": "MuJoCo",
    "mass.urdf": "MuJoCo",
    "urdf": "MuJoCo",
    "urdf.yourdfpy": "yourdfpy",
    "usd": "pxr (OpenUSD)",
    "step": "Open CASCADE",
    "legged": "MuJoCo",
    "freefall": "MuJoCo",
    "contact": "MuJoCo",
    "self_collision": "MuJoCo",
    "gpu": "MuJoCo MJX",
    "sdf": "simkit's SDFormat reader",
    "glb": "simkit's glTF reader",
    "srdf": "simkit's SRDF reader",
    "ros2": "Python ast, ElementTree",
}


def _tree(doc: dict) -> dict[str, list[tuple[str, bool]]]:
    """parent link -> [(child link, joint moves)], from robot.json's joints and fixed joints."""
    children: dict[str, list[tuple[str, bool]]] = defaultdict(list)
    for joint in doc.get("joints", []):
        children[joint["parent"]].append((joint["child"], joint.get("type") != "fixed"))
    for joint in doc.get("fixed_joints", []):
        children[joint["parent"]].append((joint["child"], False))
    return children


def _moving_below(children: dict, link: str) -> int:
    return sum(moves + _moving_below(children, child) for child, moves in children.get(link, []))


def category(doc: dict) -> str:
    """`legged`, `floating`, `arm` or `branched` (see the module docstring)."""
    children = _tree(doc)
    floating = doc.get("floating_base")
    if floating:
        root = floating["child"]
        limbs = [
            child
            for child, moves in children.get(root, [])
            if moves + _moving_below(children, child) >= LIMB_JOINTS
        ]
        return "legged" if len(limbs) >= 2 else "floating"
    branches = [
        link
        for link, kids in children.items()
        if sum(moves or _moving_below(children, child) > 0 for child, moves in kids) > 1
    ]
    return "branched" if branches else "arm"


def dof(doc: dict) -> int:
    """Moving joints (a floating base's six aside)."""
    return sum(joint.get("type") != "fixed" for joint in doc.get("joints", []))


def licence(files: dict[str, bytes]) -> str | None:
    """package.xml's `<license>` (an SPDX expression, or LicenseRef-... for the kit's own)."""
    data = files.get(layout.PACKAGE_XML)
    if data is None:
        return None
    found = ET.fromstring(data).find("license")
    return found.text.strip() if found is not None and found.text else None


def entry_points(doc: dict, files: dict[str, bytes]) -> dict[str, str]:
    """The file each tool opens first: main MJCF (the scene with a floor where there is one),
    GPU scene, URDF, USD, SDF, GLB; only those in the kit."""
    name = doc["name"]
    named = doc.get("files", {})
    candidates = {
        "mjcf": named.get("mjcf_scene") or named.get("mjcf") or layout.mjcf(name),
        "gpu_scene": (doc.get("gpu_scene") or {}).get("file") or named.get("mjcf_mjx"),
        "urdf": named.get("urdf") or layout.urdf(name),
        "usd": layout.usd(name),
        "sdf": layout.sdf(name),
        "glb": named.get("glb") or layout.glb(name),
    }
    return {key: path for key, path in candidates.items() if path and path in files}


def thumbnail(files: dict[str, bytes], entries: dict[str, str]) -> str | None:
    """The USD entry point's thumbnail (a PNG the USD emitter renders), if the kit has one."""
    if "usd" not in entries:
        return None
    path = layout.usd_thumbnail(entries["usd"])
    return path if path in files else None


def tool(check: str) -> str:
    """The tool behind a check, by the longest matching prefix of its dotted name."""
    parts = check.split(".")
    for n in range(len(parts), 0, -1):
        found = TOOLS.get(".".join(parts[:n]))
        if found:
            return found
    return "simkit"


def checks(findings) -> dict[str, dict]:
    """Findings grouped by format (the first part of the check name): passed, total, tools."""
    groups: dict[str, dict] = {}
    for finding in findings:
        group = groups.setdefault(
            finding.check.split(".")[0], {"passed": 0, "total": 0, "tools": set()}
        )
        group["passed"] += bool(finding.ok)
        group["total"] += 1
        group["tools"].add(tool(finding.check))
    return {
        key: {**value, "tools": sorted(value["tools"])} for key, value in sorted(groups.items())
    }


def facts(files: dict[str, bytes], findings) -> dict:
    """Everything the index and the pages say about one kit, from its files and findings."""
    doc = json.loads(files[layout.ROBOT_JSON])
    entries = entry_points(doc, files)
    mass = doc.get("mass", {})
    reach = (doc.get("reach") or {}).get("published") or {}
    return {
        "licence": licence(files),
        "category": category(doc),
        "dof": dof(doc),
        "mass": mass.get("model") if isinstance(mass, dict) else mass,
        "reach": reach.get("flange") or reach.get("wrist"),
        "entry_points": entries,
        "thumbnail": thumbnail(files, entries),
        "checks": checks(findings),
    }
