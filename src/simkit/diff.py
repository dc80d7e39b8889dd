"""`simkit diff OLD NEW`: what changed between two kits, for a pull request review.

Compares two kit folders or zips: joints (limits, speeds, torques, drive, origin, axis),
links (mass, CoM, inertia), links and joints added or removed (all from robot.json), meshes
whose bytes changed (volume, bounding box, triangle count), each link's number of convex
collision pieces, each STEP solid's volume and bounding box (diff_step.py), other robot.json
keys that changed, and files added, removed or changed.
Markdown for people, JSON for machines. Two kits are equal when every file is byte-identical.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from simkit.errors import SimkitError
from simkit.kitio import layout
from simkit.kitio.fmt import num
from simkit.kitio.kitread import read_folder_safely, read_zip_safely, robot_json_problem
from simkit.kitio.stl import from_stl

#: robot.json joint fields compared, with their units (angles of prismatic joints are m).
JOINT_FIELDS = {
    "type": "",
    "parent": "",
    "child": "",
    "origin_xyz": "m",
    "origin_rpy": "rad",
    "axis": "",
    "lower": "rad",
    "upper": "rad",
    "max_velocity": "rad/s",
    "effort_peak": "N m",
    "effort_continuous": "N m",
    "drive_peak_torque_at_joint": "N m",
    "armature": "kg m^2",
    "damping": "N m s/rad",
    "friction": "N m",
    "stiffness": "N m/rad",
    "springref": "rad",
    "actuated": "",
}
LINK_FIELDS = {"mass": "kg", "com": "m", "inertia": "kg m^2"}
#: robot.json keys the sections above cover (and `*_deg` twins, which follow the radians).
COVERED_KEYS = {"joints", "fixed_joints", "links"}
ANGLE_FIELDS = {"lower", "upper", "max_velocity", "origin_rpy", "springref"}
COLLISION_PIECE = re.compile(r"^meshes/collision/(.+)_(\d+)\.stl$")


@dataclass(frozen=True)
class Change:
    """One semantic change: `kind` is joint, link, mesh, collision, step or robot_json; `change`
    is modified, added or removed."""

    kind: str
    name: str
    change: str = "modified"
    field: str = ""
    old: object = None
    new: object = None
    unit: str = ""


@dataclass
class Report:
    old: str
    new: str
    changes: list[Change] = field(default_factory=list)
    added: list[str] = field(default_factory=list)
    removed: list[str] = field(default_factory=list)
    changed: list[str] = field(default_factory=list)

    @property
    def equal(self) -> bool:
        return not (self.changes or self.added or self.removed or self.changed)

    def to_json(self) -> str:
        doc = {
            "equal": self.equal,
            "old": self.old,
            "new": self.new,
            "changes": [asdict(c) for c in self.changes],
            "files": {"added": self.added, "removed": self.removed, "changed": self.changed},
        }
        return json.dumps(doc, indent=2) + "\n"


def _read_zip(path: Path) -> dict[str, bytes]:
    """Files of a kit zip, keyed by path inside the kit (`archive.read_zip`'s top-folder
    rule), read with `kitread`'s caps, or a one-line error for anything else."""
    files = read_zip_safely(path)
    tops = {name.partition("/")[0] if "/" in name else None for name in files}
    if len(tops) == 1 and None not in tops:
        return {name.partition("/")[2]: data for name, data in files.items()}
    return files


def load_kit(path: Path) -> dict[str, bytes]:
    """Files of a kit folder or kit zip, keyed by POSIX path inside the kit. A kit has a
    robot.json at its top; anything else is refused rather than reported as all removed."""
    if path.is_file():
        files = _read_zip(path)
    elif path.is_dir():
        files = read_folder_safely(path)
    else:
        raise SimkitError(f"{path}: no such kit folder or zip")
    if layout.ROBOT_JSON not in files:
        raise SimkitError(f"{path}: not a kit (no {layout.ROBOT_JSON} at its top)")
    why = robot_json_problem(files[layout.ROBOT_JSON])
    if why:
        raise SimkitError(f"{path}: {layout.ROBOT_JSON} {why}")
    return files


def _robot_json(files: dict[str, bytes]) -> dict:
    data = files.get(layout.ROBOT_JSON)
    return json.loads(data) if data else {}


def _by_name(items: list[dict]) -> dict[str, dict]:
    return {item["name"]: item for item in items}


def _flat(value):
    if isinstance(value, dict):
        return [value[k] for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz") if k in value]
    return value


def _entities(
    kind: str, old: dict[str, dict], new: dict[str, dict], fields: dict[str, str]
) -> list[Change]:
    out = [Change(kind, name, "removed") for name in old if name not in new]
    out += [Change(kind, name, "added") for name in new if name not in old]
    for name in (n for n in new if n in old):
        for key, unit in fields.items():
            a, b = _flat(old[name].get(key)), _flat(new[name].get(key))
            if a != b:
                if old[name].get("type") == "prismatic" and key in ("lower", "upper"):
                    unit = "m"
                out.append(Change(kind, name, "modified", key, a, b, unit))
    return out


def _mesh_stats(path: str, data: bytes) -> dict:
    try:
        mesh = from_stl(data)
    except (ValueError, IndexError) as exc:
        raise SimkitError(f"{path}: not a binary STL ({exc})") from None
    tri = mesh.vertices[mesh.faces]
    volume = float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6)
    size = (mesh.vertices.max(axis=0) - mesh.vertices.min(axis=0)).tolist() if len(tri) else []
    return {"volume": volume, "bbox": size, "triangles": len(mesh.faces)}


def _meshes(old: dict[str, bytes], new: dict[str, bytes]) -> list[Change]:
    out = []
    for path in sorted(set(old) & set(new)):
        if not path.endswith(".stl") or old[path] == new[path]:
            continue
        a, b = _mesh_stats(path, old[path]), _mesh_stats(path, new[path])
        for key, unit in (("volume", "m^3"), ("bbox", "m"), ("triangles", "")):
            if a[key] != b[key]:
                out.append(Change("mesh", path, "modified", key, a[key], b[key], unit))
    return out


def _pieces(files: dict[str, bytes]) -> dict[str, int]:
    count: dict[str, int] = {}
    for path in files:
        match = COLLISION_PIECE.match(path)
        if match:
            count[match.group(1)] = count.get(match.group(1), 0) + 1
    return count


def diff_files(
    old: dict[str, bytes], new: dict[str, bytes], old_name: str = "old", new_name: str = "new"
) -> Report:
    """The report for two kits given as {path: bytes}."""
    report = Report(old_name, new_name)
    report.removed = sorted(set(old) - set(new))
    report.added = sorted(set(new) - set(old))
    report.changed = sorted(p for p in set(old) & set(new) if old[p] != new[p])
    a, b = _robot_json(old), _robot_json(new)
    report.changes += _entities(
        "joint",
        _by_name(a.get("joints", []) + a.get("fixed_joints", [])),
        _by_name(b.get("joints", []) + b.get("fixed_joints", [])),
        JOINT_FIELDS,
    )
    report.changes += _entities(
        "link", _by_name(a.get("links", [])), _by_name(b.get("links", [])), LINK_FIELDS
    )
    report.changes += _meshes(old, new)
    if any(p.endswith(".step") and p in new and old[p] != new[p] for p in old):
        from simkit.diff_step import step_changes

        report.changes += step_changes(old, new, Change)
    pieces_a, pieces_b = _pieces(old), _pieces(new)
    for link in sorted(set(pieces_a) | set(pieces_b)):
        if pieces_a.get(link, 0) != pieces_b.get(link, 0):
            report.changes.append(
                Change(
                    "collision",
                    link,
                    "modified",
                    "pieces",
                    pieces_a.get(link, 0),
                    pieces_b.get(link, 0),
                )
            )
    keys = [k for k in b if k in a] + [k for k in a if k not in b] + [k for k in b if k not in a]
    for key in keys:
        if key in COVERED_KEYS or a.get(key) == b.get(key):
            continue
        kind = "added" if key not in a else "removed" if key not in b else "modified"
        report.changes.append(Change("robot_json", key, kind))
    return report


def diff_kits(old: Path, new: Path) -> Report:
    """Compare two kit folders or zips."""
    return diff_files(load_kit(old), load_kit(new), str(old), str(new))


def value_text(value, unit: str, field_name: str) -> str:
    if value is None:
        return "-"
    if isinstance(value, (bool, str)):
        return str(value)
    if isinstance(value, (int, float)):
        text = f"{num(value, 6)} {unit}".rstrip()
        if unit.startswith("rad") and field_name in ANGLE_FIELDS:
            text += f" ({num(math.degrees(value), 5)} deg{unit[3:]})"
        return text
    return f"({', '.join(num(v, 6) for v in value)}) {unit}".rstrip()


def delta_text(change: Change) -> str:
    a, b = change.old, change.new
    if isinstance(a, bool) or isinstance(b, bool):
        return ""
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        rel = f", {num(100 * (b - a) / a, 3)} %" if a else ""
        return f"{'+' if b >= a else ''}{num(b - a, 6)} {change.unit}".rstrip() + rel
    numeric = isinstance(a, list) and isinstance(b, list) and len(a) == len(b)
    if numeric and all(isinstance(v, (int, float)) for v in a + b):
        deltas = ", ".join(num(y - x, 6) for x, y in zip(a, b, strict=True))
        return f"({deltas}) {change.unit}".rstrip()
    return ""


TITLES = {
    "joint": "Joints",
    "link": "Links",
    "mesh": "Meshes",
    "collision": "Collision pieces",
    "step": "STEP solids (assembly frame, mm)",
    "robot_json": "Other robot.json entries",
}


def to_markdown(report: Report) -> str:
    """The report as Markdown, for a pull request comment."""
    lines = [f"# simkit diff: `{report.old}` -> `{report.new}`", ""]
    if report.equal:
        return "\n".join([*lines, "No changes: every file is byte-identical.", ""])
    lines += [
        f"{len(report.changes)} semantic change(s); files: {len(report.added)} added, "
        f"{len(report.removed)} removed, {len(report.changed)} changed.",
        "",
    ]
    for kind, title in TITLES.items():
        items = [c for c in report.changes if c.kind == kind]
        if not items:
            continue
        lines += [f"## {title}", ""]
        for c in items:
            if c.change != "modified":
                lines.append(f"- `{c.name}` {c.change}")
        modified = [c for c in items if c.change == "modified"]
        if modified and kind == "robot_json":
            lines += [f"- `{c.name}` changed" for c in modified]
        elif modified:
            lines += ["| name | field | old | new | change |", "|---|---|---|---|---|"]
            lines += [
                f"| `{c.name}` | {c.field} | {value_text(c.old, c.unit, c.field)} | "
                f"{value_text(c.new, c.unit, c.field)} | {delta_text(c)} |"
                for c in modified
            ]
        lines.append("")
    lines += ["## Files", ""]
    for label, paths in (
        ("added", report.added),
        ("removed", report.removed),
        ("changed", report.changed),
    ):
        if paths:
            lines.append(f"- {label}: " + ", ".join(f"`{p}`" for p in paths))
    return "\n".join([*lines, ""])
