"""URDF names simkit cannot use, renamed (one report line each) before the spec is written.

URDF allows any string (`link_11.0_tip`, `l-arm`); a spec name is an identifier that must not
collide with a name simkit generates (`X_visual` beside link `X`) nor differ from another
only by case (`spec/names.py`). The importer renames what breaks those rules to the nearest
legal name and reports it, so that the kit builds; the kit's URDF carries the new names.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from types import SimpleNamespace
from types import SimpleNamespace as NS

from simkit.importer.draft import Draft
from simkit.spec.names import MAX_NAME, problems

#: spec keys holding link, joint or frame names: (list key, fields)
_REFS = {"links": ("name",), "joints": ("name", "parent", "child"), "frames": ("name", "parent")}
_SUFFIX = {"links": "_link", "joints": "_jnt", "frames": "_frame"}
ROUNDS = 8


def _spelled(name: str) -> str:
    """`name` in the identifier grammar: other characters become `_`, a leading digit gets
    an `n` in front, and it is cut to the length cap."""
    out = re.sub(r"[^A-Za-z0-9_]", "_", name) or "unnamed"
    out = out if not out[0].isdigit() else f"n{out}"
    return out[: MAX_NAME - 8]


def _problems(spec: dict) -> dict[tuple[str, int, str], str]:
    """(list key, index, field) -> why, for each link, joint or frame name (or a frame's
    URDF joint name) the spec refuses."""
    out: dict[tuple[str, int, str], str] = {}
    for loc, why in problems(SimpleNamespace(**_construct(spec))):
        if len(loc) == 3 and loc[0] in _REFS and loc[2] in ("name", "joint"):
            out.setdefault((str(loc[0]), int(loc[1]), str(loc[2])), why)
        elif tuple(loc) == ("root",):  # a root frame (massless URDF root) is no list item
            out.setdefault(("root", -1, "name"), why)
    return out


def _construct(spec: dict) -> dict:
    """Just what `spec.names.problems` reads, as plain objects with a `name`."""
    keys = ("links", "joints", "frames", "materials", "planning_groups")
    out: dict = {
        k: [NS(name=item["name"], joint=item.get("joint")) for item in spec.get(k, [])]
        for k in keys
    }
    out.update(name=spec["name"], root=spec["root"], poses={}, poses_deg={}, mjcf=None)
    out.update(freefall=None, wrist_centre=None, tool_frame=None)
    return out


def make_legal(spec: dict, say: Callable[[str, str, str], None]) -> dict[str, dict[str, str]]:
    """Rename (in place, with every reference) the links, joints and frames whose names the
    spec refuses; one `changed` line each at the source element (`say(tag, source name,
    message)`: Draft.note_named). Returns {"links" | "joints" |
    "frames": {URDF name: spec name}} for what was renamed."""
    original: dict[str, str] = {}  # a renamed name -> the URDF's
    final: dict[str, dict[str, str]] = {}
    for _ in range(ROUNDS):
        bad = _problems(spec)
        if not bad:
            return final
        taken = {n.lower() for key in _REFS for n in (i["name"] for i in spec.get(key, []))}
        taken |= {f["joint"].lower() for f in spec.get("frames", []) if f.get("joint")}
        renames: dict[str, dict[str, str]] = {}
        for (key, index, field), why in sorted(bad.items()):
            if key == "root":  # renamed like a frame
                old, kind = spec["root"], "frames"
            else:
                old = spec[key][index][field]
                kind = "joints" if field == "joint" else key  # a frame's joint is a joint name
            new = _spelled(old)
            if new == old or new.lower() in taken:
                new = f"{new}{_SUFFIX[kind]}"
            count = 2
            base = new
            while new.lower() in taken:
                new, count = f"{base}{count}", count + 1
            taken.add(new.lower())
            renames.setdefault(kind, {})[old] = new
            original[new] = urdf = original.get(old, old)
            final.setdefault(kind, {})[urdf] = new
            tag = "joint" if kind == "joints" else "link"
            say(tag, urdf, f"renamed to '{new}' ({why})")
        _apply(spec, renames)
    return final


def _apply(spec: dict, renames: dict[str, dict[str, str]]) -> None:
    """Replace old names by new ones wherever the spec refers to them."""
    links = {**renames.get("links", {}), **renames.get("frames", {})}
    joints = renames.get("joints", {})
    for key, fields in _REFS.items():
        for item in spec.get(key, []):
            for field in fields:
                table = joints if key == "joints" and field == "name" else links
                item[field] = table.get(item[field], item[field])
            if key == "frames" and item.get("joint"):
                item["joint"] = joints.get(item["joint"], item["joint"])
            mimic = item.get("mimic")
            if mimic is not None:
                mimic["joint"] = joints.get(mimic["joint"], mimic["joint"])
    for key in ("root", "tool_frame", "wrist_centre"):
        if key in spec:
            spec[key] = links.get(spec[key], spec[key])


def legal(draft: Draft) -> None:
    """The import's step: the draft's names made legal (`make_legal`), its renames kept."""
    draft.renames = make_legal(draft.spec, draft.note_named)
    draft.changed()
