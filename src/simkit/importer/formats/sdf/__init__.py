"""SDFormat: a `.sdf` file (root element `<sdf>`) or a Gazebo model folder (`model.config`).

- `read`: the file confined and bounded, its includes expanded and its one model found
  (reader.py, files.py), then made the source model the shared translation takes
  (`source.robot`, read/model.py) by simkit's own reader of SDFormat's frame semantics
  (frames.py, tree.py; tested against Drake's parser), the base fixed where a joint mounts
  the model on the world or it is `<static>`; a second parent joint (a closed loop) is left
  out as for a URDF;
- `keep`: the model file byte for byte and every file it read (kept.py), and the shared
  differences (formats/provenance.py, which reads the model as read written as a URDF
  document, formats/urdf/document.py);
- no `EDITS` or `AFTER` of its own.
"""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

from simkit.importer.formats import provenance
from simkit.importer.formats.sdf import kept, reader, tree
from simkit.importer.formats.urdf.document import document
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.source import Source

#: the kit's own words for the source, in report lines and the spec's header
NOUN = "SDF"


def locate(path: Path) -> Path | None:
    """The SDF file of a Gazebo model folder (its model.config names it), else None."""
    return reader.main_file(path)


def sniff(path: Path, head: bytes) -> bool:
    """Whether the file's root element is `<sdf>` (its head, comments removed)."""
    return re.match(rb"\s*<\s*sdf[\s>/]", head) is not None


def title(head: bytes) -> str | None:
    """The first `<model name="...">`: the name the model's authors gave it (a world's
    first model may be scenery: the file's name then)."""
    if re.search(rb"<\s*world[\s>]", head):
        return None
    found = re.search(rb"<\s*model\b[^>]*?\bname\s*=\s*([\"'])([^\"']*)\1", head)
    return found.group(2).decode("utf-8", "replace") if found else None


def read(shell: Source, options: ReadOptions) -> Source:
    """The model read and made the source model; the base a world joint or `<static>` fixes."""
    source = reader.read(shell, options)
    source.robot, world = tree.to_robot(source)
    if world or source.static:
        why = f"joint '{world[0]}' mounts it on the world" if world else "the model is <static>"
        source.base = (False, f"fixed base: {why}; --floating-base frees it")
    source.kept = replace(source, root=document(source.robot))
    return source


def keep(draft) -> None:
    """The SDF as read and its files kept (kept.py); `source` and `source_differences`."""
    provenance.record(draft, kept.keep(draft, draft.kept))


EDITS = ()
AFTER = ()
