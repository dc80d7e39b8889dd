"""MJCF: a MuJoCo model file (root element `<mujoco>`), read by MuJoCo itself (issue 31).

- `read`: the file confined and bounded, compiled by MuJoCo (reader.py), then its robot
  made the source model the shared translation takes (`Source.robot`, tree.py; meshes
  written as STL into a scratch folder the import removes), its body welds closure joints
  (welds.py), the elements a kit cannot carry listed (listed.py), the base floating where
  the root body has a free joint (`Source.base`), and the model kept as a URDF document
  (`kept.root`, formats/urdf/document.py) for the source differences (provenance.py);
- `keep`: the model file byte for byte and every file it read (kept.py), and the
  differences: the shared ones (formats/provenance.py) and the listed ones;
- `EDITS`: the model's contact excludes carried into the spec (excludes.py);
- `AFTER`: a free base that falls on the kit's servos is marked as needing active balance
  (fixups/falling.py; the kit says so, its legged check holds the base suspended).
"""

from __future__ import annotations

import re
import shutil
import tempfile
from dataclasses import replace
from pathlib import Path

from simkit.importer.fixups import falling, settle
from simkit.importer.formats import provenance
from simkit.importer.formats.mjcf import excludes, kept, reader, tree
from simkit.importer.formats.mjcf.reader import MjcfSource
from simkit.importer.formats.urdf.document import document
from simkit.importer.read.lenient import Position
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.source import Source

#: the kit's own words for the source, in report lines and the spec's header
NOUN = "MJCF"


def sniff(path: Path, head: bytes) -> bool:
    """Whether the file's root element is `<mujoco>` (its head, comments removed)."""
    return re.match(rb"\s*<\s*mujoco[\s>/]", head) is not None


def title(head: bytes) -> str | None:
    """The `<mujoco model="...">` attribute, or None: the name a model's authors gave it,
    where robot collections name every file `robot.xml`."""
    found = re.search(rb"<\s*mujoco\b[^>]*?\bmodel\s*=\s*([\"'])([^\"']*)\1", head)
    return found.group(2).decode("utf-8", "replace") if found else None


def read(shell: Source, options: ReadOptions) -> MjcfSource:
    """The model compiled by MuJoCo and its robot's source model, the base its free joint
    says, the model written as a URDF document kept for the source differences."""
    source = reader.read(shell, options)
    scratch = Path(tempfile.mkdtemp(prefix="simkit-mjcf-"))
    source.scratch.append(scratch)
    try:
        source.robot, floating, source.listed = tree.to_robot(source, scratch)
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    source.packages.allow_read = (*source.packages.allow_read, scratch.resolve())
    source.base = (
        bool(floating),
        "floating base: the MJCF's root body has a free joint; --fixed-base bolts it"
        if floating
        else "fixed base: the MJCF's root body has no free joint; --floating-base frees it",
    )
    source.kept = replace(source, root=document(source.robot))  # provenance reads it
    return source


def carry_excludes(draft) -> None:
    """The model's contact excludes into the spec; those it cannot carry are listed."""
    listed = excludes.carry(draft.spec, draft.source, draft.renames)
    draft.kept.listed = [*draft.kept.listed, *listed]


def mark_falling(draft) -> None:
    """A floating MJCF robot that does not stand on the kit's servos (fixups/falling.py: a
    passive biped, an RL humanoid on round feet) is built, not refused: the spec's
    `needs_active_balance` gives the settle's figures (and, where the MJCF drives its joints
    by torque `<motor>`s, says so), robot.json and the README say the robot needs active
    balance, and the legged check holds its base suspended instead of standing. One report
    line, at the free joint's line."""
    drop = falling.sinks(draft)
    if drop is None:
        return
    model = draft.kept.model
    motors = any(
        model.actuator_gaintype[a] == 0 and model.actuator_biastype[a] == 0 for a in range(model.nu)
    )
    why = "; torque <motor>s drive its joints in the MJCF" if motors else ""
    reason = (
        f"on the kit's position servos at home its base sinks {drop:.2f} m in "
        f"{settle.SECONDS:g} s{why}"
    )
    draft.spec["needs_active_balance"] = reason
    draft.changed()
    free = [j for j in range(model.njnt) if model.jnt_type[j] == 0]
    line = draft.kept.lines.get(("jnt", free[0])) if free else None
    draft.report.changed(
        draft.kept,
        Position("freejoint", line),
        f"a free base that needs active balance ({reason}; a kit carries no balance "
        "controller): built, said in robot.json and the README; the legged check holds the "
        "base suspended instead of standing",
    )


def keep(draft) -> None:
    """The MJCF as read and its files kept (kept.py); `source` and `source_differences`."""
    provenance.record(draft, kept.keep(draft, draft.kept))


EDITS = (carry_excludes,)
AFTER = (mark_falling,)
