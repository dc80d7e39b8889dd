"""URDF: a `.urdf` file (and any file no other format claims; formats.FORMATS's last row).

- `read`: lxml parse (parse.py), leftover `$(...)` substitutions expanded, the document kept
  as read (`Source.kept`), then the source repairs (repairs.py: an undeclared mounting frame
  declared, identical duplicates dropped), each reported;
- `keep`: the document as read, re-serialised, kept as `NAME.source.urdf` beside the spec
  (formats/provenance.py lists its differences with the kit);
- `EDITS`: the URDF blocks the kit carries verbatim (blocks.py: `<gazebo>`,
  `<transmission>`, `<ros2_control>`), renamed as the spec was.

The xacro format (formats/xacro.py) expands the file, then reads it as this one does.
"""

from __future__ import annotations

from pathlib import Path

from simkit.importer.formats import provenance
from simkit.importer.formats.urdf import blocks, parse, repairs
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.source import Source

#: the kit's own words for the source, in report lines and the spec's header
NOUN = "URDF"


def sniff(path: Path, head: bytes) -> bool:
    """Every file: the URDF reader says in one line what is wrong with one that is not."""
    return True


def title(head: bytes) -> str | None:
    """A URDF's robot name is no spec name (robot collections reuse them): the file's."""
    return None


def read(shell: Source, options: ReadOptions) -> Source:
    """The `.urdf` parsed, leftover substitutions expanded, kept as read, then repaired."""
    return repaired(parse.read(shell, options))


def repaired(source: Source) -> Source:
    """`source` (a parsed URDF) kept as read (`kept`), then its repairs applied in place:
    an include expanded twice, an undeclared frame the robot is mounted on, a second parent
    joint (a closed loop)."""
    source.kept = provenance.as_read(source)
    repairs.identical_duplicates(source, source.report)
    repairs.mounting_frame(source, source.report)
    return source


def keep(draft) -> None:
    """Write the URDF as read (`draft.kept`) into the staging folder as NAME.source.urdf,
    and add `source` and `source_differences` to the spec."""
    original = draft.kept
    data = serialised(original)
    spec = draft.spec
    name = f"{spec['name']}.source.urdf"
    (draft.stage / name).write_bytes(data)
    spec["source"] = provenance.entry(draft, name, data)
    listed = provenance.differences(spec, original, draft.report, draft.renames)
    spec["source_differences"] = provenance.merged(listed, draft.listed)
    draft.changed()


def serialised(kept: Source) -> bytes:
    """The kept URDF's bytes: the document as read, re-serialised (comments dropped). The
    source check makes them again from the original file (check/source/urdf.py)."""
    from lxml import etree

    data = etree.tostring(kept.root.getroottree(), xml_declaration=True, encoding="utf-8")
    return data.rstrip(b"\n") + b"\n"


def keep_blocks(draft) -> None:
    """The spec's `urdf_blocks`: the document's blocks, renamed as the spec was (blocks.py)."""
    source = draft.source
    blocks.keep(draft.spec, source, draft.report, blocks.collect(source), draft.renames)


EDITS = (keep_blocks,)
AFTER = ()
