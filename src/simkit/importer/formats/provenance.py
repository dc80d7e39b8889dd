"""Where the kit came from and where it differs, shared by the formats' `keep`.

Each format keeps its source beside the spec (formats/urdf: `NAME.source.urdf`, the
document the importer read, xacro expanded, comments dropped; formats/mjcf: the model and
its files), records its SHA-256 in the spec's `source`, and lists every intended difference
between the kit and that source in `source_differences`, each with its reason
(`differences`, here). The build's source check (check/source) re-reads the kept file with
a reader other than the importer's and fails on any difference not listed. Keys use the
URDF's names: `links.L.FIELD`, `joints.J.FIELD`, `links.L.name` (renamed, `kit` = new name),
`links.NAME` / `joints.NAME` (added by the kit).
"""

from __future__ import annotations

import hashlib
from dataclasses import replace

from simkit.importer.diagnostics import Report
from simkit.importer.read.source import Source, describe, line_of
from simkit.kitio.oneline import one_line
from simkit.spec.bounds import MAX_STRING

#: spec fields of a link or joint the source check compares, as its `estimated` names them
COMPARED = {
    "links": ("mass", "com", "inertia"),
    "joints": ("lower", "upper", "max_velocity", "effort_peak"),
}
GENERIC = {
    "mass": "the URDF gives no usable mass: estimated",
    "com": "the URDF gives no centre of mass: estimated",
    "inertia": "the URDF's inertia is missing or cannot be simulated: estimated",
    "lower": "the URDF gives no usable position limits: estimated",
    "upper": "the URDF gives no usable position limits: estimated",
    "max_velocity": "the URDF's velocity limit is missing or a placeholder: estimated",
    "effort_peak": "the URDF's effort limit is missing or a placeholder: estimated",
}


def entry(draft, name: str, data: bytes) -> dict:
    """The spec's `source` entry of a kept file `name` holding `data`: its digest, the
    format, and the original's digest and the --xacro-arg values where they matter (the
    kept file is not the original byte for byte; the file was read with arguments)."""
    source = draft.source
    out = {"file": name, "format": source.format, "sha256": hashlib.sha256(data).hexdigest()}
    if source.original and source.original != out["sha256"]:
        out["original"] = source.original
    if source.args:
        out["args"] = dict(sorted(source.args.items()))
    return out


def as_read(source: Source) -> Source:
    """The document as the importer read it (xacro expanded), copied before any repair or
    rewrite (a spherical joint becomes three joints in place, ball_joints.py): what the kit
    is compared with. Line numbers are kept, so report lines still match its elements."""
    import copy

    return replace(source, root=copy.deepcopy(source.root))


def record(draft, source_entry: dict) -> None:
    """The spec's `source` (the kept files' entry a format's `keep` made) and its
    `source_differences` (the shared ones and the format's listed ones): the end of every
    format's `keep`."""
    original, spec = draft.kept, draft.spec
    spec["source"] = source_entry
    listed = differences(spec, original, draft.report, draft.renames)
    spec["source_differences"] = merged(listed, [*original.listed, *draft.listed])
    draft.changed()


def merged(listed: list[dict], extra: list[tuple[str, str]]) -> list[dict]:
    """`listed` with each (what, reason) of `extra` whose `what` it lacks, sorted by `what`."""
    seen = {d["what"] for d in listed}
    more = [{"what": one_line(w), "reason": one_line(r)} for w, r in extra]
    return sorted(listed + [d for d in more if d["what"] not in seen], key=lambda d: d["what"])


def differences(
    spec: dict, source: Source, report: Report, renames: dict[str, dict[str, str]]
) -> list[dict]:
    """Every intended difference between the spec's kit and the URDF, sorted by `what`."""
    back = {new: old for table in renames.values() for old, new in table.items()}
    out: dict[str, dict] = {}

    def add(what: str, reason: str, kit: str | None = None) -> None:
        what, reason = one_line(what), one_line(reason)  # URDF names may hold a newline
        if len(reason) > MAX_STRING:  # a one-line URDF: every report line matches its line
            reason = reason[: MAX_STRING - 3] + "..."
        out.setdefault(what, {"what": what, "reason": reason, **({"kit": kit} if kit else {})})

    for kind, table in sorted(renames.items()):
        key = "joints" if kind == "joints" else "links"
        for old, new in sorted(table.items()):
            add(f"{key}.{old}.name", f"renamed: '{old}' is not a name the kit can hold", new)
    _added(spec, source, back, add)
    _frames(spec, source, back, add)
    records = Said(report)
    _reshaped(spec, source, records, back, add)
    for kind, fields in COMPARED.items():
        tag = kind[:-1]
        named: dict = {}  # the first element of each name, as `find` gives it
        for element in source.root.findall(tag):
            named.setdefault(element.get("name"), element)
        for item in spec.get(kind, []):
            old = back.get(item["name"], item["name"])
            element = named.get(_quoted(old))
            said = _said(records, source, element)
            for field in item.get("estimated", []):
                if field in fields:
                    generic = GENERIC[field].replace("URDF", source.noun)
                    add(f"{kind}.{old}.{field}", said or generic)
            if kind == "links" and element is not None:
                _dropped(records, source, element, f"links.{old}", add)
            if kind == "links" and item.get("inertia_decision"):
                add(f"links.{old}.inertia", item["inertia_decision"]["reason"])
            if kind == "joints" and element is not None and element.get("type") != item["type"]:
                kind_in = f"a {element.get('type')} joint in the {source.noun}"
                add(f"joints.{old}.type", said or kind_in)
    _massless(source, add)
    _loops(source, records, add)
    return [out[k] for k in sorted(out)]


def _loops(source: Source, report: Said, add) -> None:
    """A joint whose child link already hangs from an earlier joint (a closed loop) is not
    a tree joint of the kit, which closes the loop with a weld (importer/translate/loops.py):
    listed as `joints.J` with its report line."""
    parented: set[str] = set()
    for joint in source.root.findall("joint"):
        child = joint.find("child")
        link = None if child is None else child.get("link")
        if link in parented:
            said = _said(report, source, joint) or "a second parent joint: closed by a weld"
            add(f"joints.{joint.get('name')}", said)
        parented.add(link)


def _massless(source: Source, add) -> None:
    """A URDF link of zero mass with an `<inertial>` (a frame, a `world` root) gives its CoM
    and inertia no meaning: a body without mass has none, and the kit writes none (after
    the listed estimates, which take precedence)."""
    for link in source.root.iter("link"):
        mass = link.find("inertial/mass")
        try:
            massless = mass is not None and float(mass.get("value", "0")) == 0.0
        except ValueError:
            massless = False
        if massless:
            reason = (
                f"a massless link in the {source.noun}: a body without mass has no CoM or inertia"
            )
            add(f"links.{link.get('name')}.com", reason)
            add(f"links.{link.get('name')}.inertia", reason)


def _added(spec: dict, source: Source, back: dict[str, str], add) -> None:
    """A fixed base bolts the URDF's root link to a root frame (`world`) the URDF lacks."""
    root = spec["root"]
    old = _quoted(back.get(root, root))
    if source.root.find(f"link[@name='{old}']") is not None:
        return  # the URDF's own massless root link is the kit's root
    if source.root.find(f"joint/parent[@link='{old}']") is not None:  # formats/urdf/repairs.py
        said = f"added: the frame the {source.noun} mounts the robot on, named, not declared"
        add(f"links.{root}", said)
        return
    for joint in spec["joints"]:
        if joint["parent"] == root and joint["type"] == "fixed":
            add(f"links.{root}", "added: the world the fixed base is bolted to")
            said = f"added: bolts the {source.noun}'s root link to the world"
            add(f"joints.{joint['name']}", said)


#: joint fields the source check compares, listed for a joint the kit had to reshape
RESHAPED = ("parent", "origin", "axis", "lower", "upper", "max_velocity", "effort_peak")


def _reshaped(spec: dict, source: Source, report: Said, back: dict[str, str], add) -> None:
    """A URDF joint of a type the kit has no equivalent for (PyBullet's `spherical`) becomes
    several kit joints through links the URDF lacks: the URDF joint's compared fields, and
    each kit link or joint the URDF lacks, are listed with the import's report line."""
    kinds = {"revolute", "continuous", "prismatic", "fixed", "floating", "planar"}
    for element in source.root.findall("joint"):  # the robot's joints, not a block's
        if element.get("type") in kinds or not element.get("name"):
            continue
        said = _said(report, source, element) or (
            f"a {element.get('type')} joint in the {source.noun}"
        )
        name = element.get("name")
        for field in RESHAPED:
            add(f"joints.{name}.{field}", said)
        for kind, tag in (("links", "link"), ("joints", "joint")):
            for item in spec.get(kind, []):
                old = back.get(item["name"], item["name"])
                if source.root.find(f"{tag}[@name='{_quoted(old)}']") is None and (
                    old.startswith(name)
                ):
                    add(f"{kind}.{old}", f"added: {said}")


def _frames(spec: dict, source: Source, back: dict[str, str], add) -> None:
    """A massless, geometry-free leaf on a fixed joint is a kit frame, whose fixed joint the
    kit's URDF names `FRAME_joint` (emit/urdf.py)."""
    for frame in spec.get("frames", []):
        old = back.get(frame["name"], frame["name"])
        for joint in source.root.findall("joint"):
            child = joint.find("child")
            if child is not None and child.get("link") == old:
                kit = frame.get("joint", f"{frame['name']}_joint")
                if joint.get("name") != kit:
                    reason = "the massless leaf link is a kit frame, its joint named FRAME_joint"
                    add(f"joints.{joint.get('name')}.name", reason, kit)


def _dropped(report: Said, source: Source, link, key: str, add) -> None:
    """A visual or collision element the import left out (unreadable mesh, a primitive below
    a millimetre, ...): listed for the record (the check compares no geometry)."""
    for tag in ("visual", "collision"):
        said = [
            m.split(": ", 1)[-1]
            for part in link.findall(tag)
            for m in _said(report, source, part).split("; ")
            if m.startswith(f"not imported: {tag} ")
        ]
        if said:
            add(f"{key}.{tag}", "left out: " + "; ".join(said[:4]))


class Said:
    """The report's records about each source element, indexed by (file name, line,
    element), so that finding an element's records takes time in its records, not in the
    report's (a chain of thousands of links has thousands of each). A record of no known
    line names no element of the kept source."""

    def __init__(self, report: Report) -> None:
        self.index: dict[tuple[str, int, str], list[tuple[int, str]]] = {}
        for i, record in enumerate(report.records):
            if record.line is not None:
                key = (record.file.name, record.line, record.element)
                self.index.setdefault(key, []).append((i, f"{record.kind}: {record.message}"))


def _said(report: Said, source: Source, element) -> str:
    """The report's `KIND: message` about `element` or an element inside it, in report
    order, the first four joined by '; '."""
    if element is None:
        return ""
    keys = {(source.path.name, line_of(e), describe(e)) for e in element.iter()}
    hits = sorted(hit for key in keys for hit in report.index.get(key, ()))
    return "; ".join(said for _, said in hits[:4])


def _quoted(name: str) -> str:
    """A name usable inside an XPath `[@name='...']` (one with a quote matches nothing)."""
    return name if "'" not in name else "\0"
