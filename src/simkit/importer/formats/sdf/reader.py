"""The SDFormat reader: the file (or a Gazebo model folder's), its version, the one model it
holds, `<include>`s expanded, mesh URIs resolved, and the extensions a kit drops listed.

- Versions 1.4 to 1.11 (`<sdf version>`); others are one line.
- `<world>`: its one robot (the one model with a joint; static scenery beside it is dropped,
  one line each); several robots are one line.
- `<include>`: the included model becomes a nested `<model>` (names scoped `a::b`), or with
  `merge="true"` its elements join the including model, the included model frame becoming
  the frame `_merged__NAME__model__` (as the specification defines it).
- Mesh `<uri>`s are replaced by the file they name (files.py confines them); a missing one
  is dropped by the translation with one line, as for a URDF (`--strict` refuses it).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simkit.errors import SpecError
from simkit.importer.formats.sdf import files as sdf_files
from simkit.importer.formats.sdf.frames import pose_of
from simkit.importer.read.source import Source

#: elements a kit carries nothing of: one report line each (dropped)
EXTENSIONS = {
    "plugin": "a simulator plugin (code a kit does not run)",
    "sensor": "a sensor (a kit carries no sensors)",
    "gazebo": "a Gazebo extension",
    "light": "a light",
    "audio_sink": "an audio element",
    "audio_source": "an audio element",
    "battery": "a battery",
    "projector": "a projector",
    "particle_emitter": "a particle emitter",
}


@dataclass
class SdfSource(Source):
    """A read SDFormat model: `model` (its `<model>` element, includes expanded), `files`
    (files.Files: every file read), `static`, the model's pose in its world (4x4, m)."""

    model: object = None
    files: object = None
    static: bool = False
    placed: np.ndarray = field(default_factory=lambda: np.eye(4))
    listed: list[tuple[str, str]] = field(default_factory=list)


def main_file(path: Path) -> Path | None:
    """The SDF a Gazebo model folder names (`model.config`), else None."""
    if path.is_dir() and (path / "model.config").is_file():
        return sdf_files.from_config(path.resolve(), (str(path), None, "model.config"))
    return None


def read(shell: Source, options) -> SdfSource:
    """The SDF at `shell.path` read (module docstring); one line on any problem."""
    path = shell.path.resolve()
    source = SdfSource(shell.path, None, shell.packages, shell.report)
    folder = sdf_files.model_folder(path)
    if folder is not None:
        source.packages.root = folder
    folder = folder or source.packages.root
    files = sdf_files.Files(path, folder, source.packages)
    source.files = files
    root = _load(source, files, path, (str(path), None, "file"), 0)
    _version(source, root)
    source.model = _robot(source, root)
    source.static = (source.model.findtext("static") or "").strip() in ("true", "1")
    source.placed = pose_of(source, source.model.find("pose"))
    _extensions(source, source.model)
    return source


def _load(source: SdfSource, files, path: Path, where, depth: int):
    """An SDF file parsed, its mesh URIs resolved, its includes expanded (depth-capped)."""
    if depth > sdf_files.MAX_DEPTH:
        raise SpecError(*where[:2], "include", f"includes nest over {sdf_files.MAX_DEPTH} deep")
    root = files.parse(path, where)
    if root.tag != "sdf":
        raise SpecError(str(path), root.sourceline, root.tag, "not an SDFormat file (<sdf> root)")
    for uri in root.iter("uri"):
        parent = uri.getparent()
        if parent is not None and parent.tag == "mesh":
            at = (str(path), uri.sourceline, "mesh.uri")
            found = files.uri(uri.text or "", path, at, must_exist=False)
            if found.is_file():  # else the translation drops it, one line (a URDF's rule)
                files.read(found, at)
            uri.text = Path(os.path.relpath(found, files.main.parent)).as_posix()  # no abs path
    for include in list(root.iter("include")):
        _include(source, files, path, include, depth)
    return root


def _include(source: SdfSource, files, path: Path, include, depth: int) -> None:
    """Replace `<include>` by the model it names: nested, or merged into its parent."""
    where = (str(path), include.sourceline, "include.uri")
    target = files.uri(include.findtext("uri") or "", path, where)
    if target.is_dir():
        if not (target / "model.config").is_file():
            raise SpecError(*where, f"'{include.findtext('uri')}' is a folder without model.config")
        files.read(target / "model.config", where)  # kept: the proof resolves it again
        target = sdf_files.from_config(target, where)
    inner_root = _load(source, files, target, where, depth + 1)
    _version(source, inner_root)
    inner = inner_root.find("model")
    if inner is None:
        raise SpecError(*where, f"'{include.findtext('uri')}' holds no <model>")
    inner = sdf_files.scrubbed(inner, include.sourceline)
    inner.set("name", (include.findtext("name") or inner.get("name") or "model").strip())
    for tag in ("pose", "static"):
        given = include.find(tag)
        if given is not None:
            old = inner.find(tag)
            if old is not None:
                inner.remove(old)
            inner.insert(0, given)
    parent = include.getparent()
    if include.get("merge") in ("true", "1"):
        _merge(parent, include, inner)
    else:
        parent.replace(include, inner)


def _merge(parent, include, inner) -> None:
    """The included model's elements into `parent`, its frame `_merged__NAME__model__`."""
    from lxml import etree

    name = f"_merged__{inner.get('name')}__model__"
    frame = etree.Element("frame", name=name)
    frame.sourceline = include.sourceline
    canonical = inner.get("canonical_link") or next(
        (c.get("name") for c in inner if c.tag == "link"), None
    )
    if canonical:  # the merged model frame moves with its canonical link
        frame.set("attached_to", canonical)
    pose = inner.find("pose")
    if pose is None:
        pose = etree.SubElement(frame, "pose")
        pose.text = "0 0 0 0 0 0"
    frame.append(pose)
    if not pose.get("relative_to"):
        pose.set("relative_to", "__model__")  # the including model's frame
    at = parent.index(include)
    parent.remove(include)
    parent.insert(at, frame)
    for child in [c for c in inner if c.tag in ("link", "joint", "frame", "model")]:
        _rebase(child, name)
        at += 1
        parent.insert(at, child)


def _rebase(child, frame: str) -> None:
    """References to the included model frame (`__model__`, explicit or by default) in a
    merged element made to its merged frame."""
    from lxml import etree

    for e in child.iter("pose", "xyz", "parent", "child"):
        if e.get("relative_to") == "__model__":
            e.set("relative_to", frame)
        if e.get("expressed_in") == "__model__":
            e.set("expressed_in", frame)
        if e.tag in ("parent", "child") and (e.text or "").strip() == "__model__":
            e.text = frame
    if child.get("attached_to") == "__model__":
        child.set("attached_to", frame)
    if child.tag == "joint":
        return
    pose = child.find("pose")
    if (
        child.tag == "frame"
        and child.get("attached_to")
        and (pose is None or not pose.get("relative_to"))
    ):
        return  # relative to what it is attached to
    if child.tag == "frame" and not child.get("attached_to"):
        child.set("attached_to", frame)
    if pose is None:
        pose = etree.SubElement(child, "pose")
        pose.text = "0 0 0 0 0 0"
    if not pose.get("relative_to"):
        pose.set("relative_to", frame)


def _version(source: SdfSource, root) -> None:
    text = root.get("version") or ""
    try:
        major, minor = (int(v) for v in text.split(".")[:2])
    except ValueError:
        raise source.fail(root, f"version '{text}' is not MAJOR.MINOR") from None
    if major != 1 or not 4 <= minor <= 11:
        raise source.fail(root, f"SDFormat {text}: simkit reads 1.4 to 1.11")


def _joints(model) -> int:
    return sum(1 for _ in model.iter("joint"))


def _robot(source: SdfSource, root):
    """The one model of the file (a world's one model with joints)."""
    model = root.find("model")
    if model is not None:
        return model
    world = root.find("world")
    if world is None:
        raise source.fail(root, "holds no <model> and no <world>")
    models = world.findall("model")
    robots = [m for m in models if _joints(m)] or models
    if not robots:
        raise source.fail(world, "the world holds no model")
    if len(robots) > 1:
        names = ", ".join(m.get("name") or "?" for m in robots)
        raise source.fail(robots[1], f"several robots in one world ({names}): import one per file")
    for other in models:
        if other is not robots[0] and source.report is not None:
            source.report.dropped(source, other, "scenery beside the robot in the world")
    return robots[0]


def _extensions(source: SdfSource, model) -> None:
    """Each element a kit carries nothing of: one report line (dropped), removed; what lies
    inside it is not walked (its line says it)."""
    pending = [model]
    while pending:
        for element in list(pending.pop()):
            tag = element.tag if isinstance(element.tag, str) else ""
            plain = tag.rpartition("}")[2]
            if plain not in EXTENSIONS and not tag.startswith("{"):
                pending.append(element)
                continue
            named = f"{element.prefix}:{plain}" if element.prefix else plain
            what = EXTENSIONS.get(plain, f"<{named}>, an extension of another simulator")
            if source.report is not None:
                shown = Named(named, element.sourceline, element.get("name"))
                source.report.dropped(source, shown, f"{what}: not carried by the kit")
            element.getparent().remove(element)


@dataclass
class Named:
    """An element as a report line names it (`drake:joint`, not lxml's `{URI}joint`)."""

    tag: str
    sourceline: int | None
    name: str | None

    def get(self, key: str, default=None):
        return self.name if key == "name" else default
