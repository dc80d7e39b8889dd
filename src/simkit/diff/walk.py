"""The kit walk of `simkit diff OLD NEW`: what changed between two kits, for a pull request.

Compares two kits read by `kit.load_kit`: joints (limits, speeds, torques, drive, origin,
axis), links (mass, CoM, inertia), links and joints added or removed (all from robot.json),
each mesh as a placed piece in its link frame (`mesh`), each link's number of convex
collision pieces, each STEP solid's volume and bounding box (`step`), other robot.json
values that changed, and files added, removed or changed (GLB and USD: `scene`). Every
number is compared with the tolerance the checks use for its quantity (`tolerance`): a
difference below it is round-off, not a change. Two kits are equal when nothing changed
beyond round-off; `identical` when every file is byte-identical.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from simkit.diff.kit import load_kit
from simkit.diff.mesh import mesh_changes
from simkit.diff.report import Change, Report
from simkit.diff.scene import glb_close, usd_close
from simkit.diff.stage import is_usd, stage_changes
from simkit.diff.step import step_changes
from simkit.diff.tolerance import PARAM_SI, leaf_changes, same, text_close, tolerance
from simkit.errors import SimkitError
from simkit.kitio import layout

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
#: robot.json keys that say how the kit was made (spec digest, library versions), not what it
#: is: listed apart, never a change of the kit
METADATA_KEYS = ("provenance",)
#: changed values listed per other robot.json key; the rest are counted
MAX_LEAVES = 8
COLLISION_PIECE = re.compile(r"^meshes/collision/(.+)_(\d+)\.(?:stl|obj)$")


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
        a, b = old[name], new[name]
        for key, unit in fields.items():
            if a.get("type") == "prismatic" and key in ("lower", "upper"):
                unit = "m"
            x, y = _flat(a.get(key)), _flat(b.get(key))
            if not same(x, y, tolerance(unit)):
                out.append(Change(kind, name, "modified", key, x, y, unit, tolerance(unit)))
        out += _other_fields(kind, name, a, b, fields)
    return out


def _other_fields(kind: str, name: str, a: dict, b: dict, fields: dict) -> list[Change]:
    """Fields of a joint or link beyond `fields` (drive, derived values, estimates), each
    changed value with its path; a `*_deg*` twin follows its radians and is skipped."""
    keys = [k for k in [*a, *(k for k in b if k not in a)] if k not in fields and k != "name"]
    keys = [k for k in keys if not ("_deg" in k and k.split("_deg")[0] in {*a, *b})]
    leaves = [leaf for k in keys for leaf in leaf_changes(a.get(k), b.get(k), PARAM_SI, k)]
    out = [Change(kind, name, "modified", path, x, y) for path, x, y in leaves[:MAX_LEAVES]]
    if len(leaves) > MAX_LEAVES:
        more = f"{len(leaves) - MAX_LEAVES} more values"
        out.append(Change(kind, name, "modified", "...", "-", more))
    return out


def _meshes(old: dict[str, bytes], new: dict[str, bytes]) -> list[Change]:
    out = []
    for path in sorted(set(old) & set(new)):
        if path.endswith((".stl", ".obj")) and old[path] != new[path]:
            out += mesh_changes(path, old[path], new[path])
    return out


def _pieces(files: dict[str, bytes]) -> dict[str, int]:
    count: dict[str, int] = {}
    for path in files:
        match = COLLISION_PIECE.match(path)
        if match:
            count[match.group(1)] = count.get(match.group(1), 0) + 1
    return count


def _other_entries(a: dict, b: dict) -> list[Change]:
    """Other robot.json keys: each changed value (at most MAX_LEAVES per key) with its path."""
    out = []
    keys = [k for k in b if k in a] + [k for k in a if k not in b] + [k for k in b if k not in a]
    for key in keys:
        if key in COVERED_KEYS or key in METADATA_KEYS:
            continue
        if key not in a or key not in b:
            out.append(Change("robot_json", key, "added" if key not in a else "removed"))
            continue
        leaves = list(leaf_changes(a[key], b[key], PARAM_SI))
        for path, old, new in leaves[:MAX_LEAVES]:
            out.append(Change("robot_json", key, "modified", path or key, old, new))
        if len(leaves) > MAX_LEAVES:
            more = f"{len(leaves) - MAX_LEAVES} more values"
            out.append(Change("robot_json", key, "modified", "...", "-", more))
    return out


def _round_off(path: str, old: bytes, new: bytes, changes: list[Change]) -> bool:
    """Do two versions of a file differ only below the tolerances (or in provenance)?"""
    if path == layout.ROBOT_JSON:
        return not any(c.kind in ("joint", "link", "robot_json") for c in changes)
    if path.endswith((".stl", ".obj")):
        return not any(c.kind == "mesh" and c.name == path for c in changes)
    if path.endswith(".step"):
        return not any(c.kind == "step" for c in changes)
    if path.endswith(".glb"):
        return glb_close(old, new)
    if path.endswith((".usd", ".usda", ".usdc")):
        return usd_close(path, old, new)
    return text_close(old, new)


def diff_files(
    old: dict[str, bytes], new: dict[str, bytes], old_name: str = "old", new_name: str = "new"
) -> Report:
    """The report for two kits given as {path: bytes}."""
    report = Report(old_name, new_name)
    report.removed = sorted(set(old) - set(new))
    report.added = sorted(set(new) - set(old))
    differ = sorted(p for p in set(old) & set(new) if old[p] != new[p])
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
    if any(p.endswith(".step") for p in differ):
        report.changes += step_changes(old, new)
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
    report.changes += _other_entries(a, b)
    usd = None
    if any(is_usd(p) for p in [*differ, *report.added, *report.removed]):
        usd = stage_changes(old, new)  # None: not composable, compared file by file below
        report.changes += usd or []
    for key in METADATA_KEYS:
        report.metadata += [p for p, _x, _y in leaf_changes(a.get(key), b.get(key), 0.0, key)]
    for path in differ:
        if usd is not None and is_usd(path):
            kind = not any(c.kind == "usd" for c in report.changes)
        else:
            kind = _round_off(path, old[path], new[path], report.changes)
        (report.round_off if kind else report.changed).append(path)
    return report


def diff_kits(old: Path, new: Path) -> Report:
    """Compare two kit folders or zips."""
    files = load_kit(old), load_kit(new)
    try:
        return diff_files(*files, str(old), str(new))
    except RecursionError:  # a robot.json that json reads but is too deep to compare
        raise SimkitError(f"{new}: {layout.ROBOT_JSON} is nested too deeply to compare") from None
