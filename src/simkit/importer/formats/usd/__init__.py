"""USD: a UsdPhysics articulation (`.usd`, `.usda`, `.usdc`), read from the stage usd-core
composes (issue 39).

- `read`: every layer the file composes checked to lie inside the model's folder and to be
  USD before the stage opens (confine.py), the stage composed with the `Physics` variant the
  user names (`--variant`) or its default (stage.py), its one articulation found, then made
  the source model the shared translation takes (`Source.robot`, read/model.py; tree.py,
  mass.py, shapes.py; numbers as the floats computed (one not finite: refused by formats/finite.py);
  meshes written as STL into a scratch folder the import removes); the base floats unless a
  joint holds the root body to the world; loop joints left out by the translation's
  `second_parents` (translate/loops.py); the model kept as a URDF document (`kept.root`,
  formats/urdf/document.py) for the source differences (provenance.py);
- `keep`: every layer as read, byte for byte (kept.py), the variant read in `source.args`,
  and the differences: the shared ones (formats/provenance.py) and the listed ones;
- `EDITS`: a drive force apart from the joint's own effort limit kept as the spec's
  `drive_peak_torque_at_joint` (carry_servos); the armature the USD gives as the spec's
  `armature` (carry_armatures; damping and friction travel as the model's `Dynamics`;
  a follower's NewtonMimicAPI or PhysxMimicJointAPI as its `Mimic`, mimic.py);
- `AFTER`: a free base that falls on the kit's servos is marked as needing active balance
  (fixups/falling.py), as an MJCF's is.
"""

from __future__ import annotations

import shutil
import tempfile
from dataclasses import dataclass, field, replace
from pathlib import Path

from simkit.importer.fixups import falling, settle
from simkit.importer.formats import provenance
from simkit.importer.formats.urdf.document import document
from simkit.importer.formats.usd import confine, kept, stage, tree
from simkit.importer.read.lenient import Position
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.source import Source

#: the kit's own words for the source, in report lines and the spec's header
NOUN = "USD"
SUFFIXES = (".usd", ".usda", ".usdc")


def sniff(path: Path, head: bytes) -> bool:
    """A `.usd`, `.usda` or `.usdc` file (a text layer starts `#usda`, a crate `PXR-USDC`)."""
    return path.suffix.lower() in SUFFIXES or head.startswith((b"#usda", b"PXR-USDC"))


def title(head: bytes) -> str | None:
    """No name from the head: the spec is named after the file."""
    return None


@dataclass
class UsdSource(Source):
    """A read USD: the layers' bytes (`files`, relative to the model's folder), the
    variant read and the listed differences."""

    files: dict[str, bytes] = field(default_factory=dict)
    variant: str | None = None
    listed: list[tuple[str, str]] = field(default_factory=list)
    #: joint name -> the drive's force (N m or N) apart from its effort limit (tree.py)
    servos: dict[str, float] = field(default_factory=dict)
    #: joint name -> the armature the USD gives (kg m^2 or kg; formats/usd/dynamics.py)
    armatures: dict[str, float] = field(default_factory=dict)


def read(shell: Source, options: ReadOptions) -> Source:
    """The composed stage's articulation as the source model (module docstring)."""
    allowed = (shell.path.resolve().parent, *(p.resolve() for p in options.allow_read))
    layers = confine.open_layers(shell.path, allowed)
    opened, variant = stage.open_stage(shell.path, layers.root, options.variant)
    art = stage.articulation(shell.path, opened)
    art.variant = variant
    scratch = Path(tempfile.mkdtemp(prefix="simkit-usd-"))
    source = UsdSource(shell.path, None, shell.packages, shell.report)
    source.scratch.append(scratch)
    try:
        robot, floating, listed, dropped, ctx = tree.to_robot(art, scratch)
        source.robot = robot
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    source.servos, source.armatures = ctx.servos, ctx.armatures
    source.packages.allow_read = (*source.packages.allow_read, scratch.resolve())
    source.files, source.variant, source.listed = layers.files, variant, listed
    for note in art.notes:
        source.note(Position("stage", None), note)
    for joint, why in dropped:
        source.note(Position(f"joint {joint.GetPath()}", None), f"not imported: {why}")
    for where, why in ctx.notes:
        source.note(Position(where, None), why)
    source.base = (
        floating,
        "floating base: no joint holds the USD's root body to the world; --fixed-base bolts it"
        if floating
        else "fixed base: a joint holds the USD's root body to the world; --floating-base frees it",
    )
    source.kept = replace(source, root=document(source.robot))  # provenance reads it
    return source


def keep(draft) -> None:
    """Every layer as read (kept.py); `source` and `source_differences`."""
    provenance.record(draft, kept.keep(draft, draft.kept))


def mark_falling(draft) -> None:
    """A floating robot that does not stand on the kit's servos (fixups/falling.py: a
    humanoid made for a balance controller) is built, not refused, as for an MJCF: the
    spec's `needs_active_balance` gives the settle's figures, robot.json and the README say
    so, and the legged check holds its base suspended. One report line."""
    drop = falling.sinks(draft)
    if drop is None:
        return
    reason = (
        f"on the kit's position servos at home its base sinks {drop:.2f} m in {settle.SECONDS:g} s"
    )
    draft.spec["needs_active_balance"] = reason
    draft.changed()
    draft.report.changed(
        draft.kept,
        Position("stage", None),
        f"a free base that needs active balance ({reason}; a kit carries no balance "
        "controller): built, said in robot.json and the README; the legged check holds the "
        "base suspended instead of standing",
    )


def carry_servos(draft) -> None:
    """A joint whose USD carries its own effort limit (`simkit:effortLimit`, the spec's
    effort_peak) and a drive `maxForce` apart from it (a simkit kit's servo force): the spec
    keeps the force as `drive_peak_torque_at_joint` (the kit's servo force range), so both
    come back as they were; a force equal to the limit adds nothing."""
    servos = getattr(draft.source, "servos", {})
    back = {new: old for old, new in draft.renames.get("joints", {}).items()}
    for joint in draft.spec.get("joints", []):
        force = servos.get(back.get(joint["name"], joint["name"]))
        effort = joint.get("effort_peak")
        if force is None or effort is None or abs(force - effort) <= 1e-9 * effort:
            continue
        joint["drive_peak_torque_at_joint"] = force
        draft.changed()


def carry_armatures(draft) -> None:
    """A joint whose USD gives its armature (formats/usd/dynamics.py: MjcPhysics or PhysX)
    keeps it as the spec's `armature` (kg m^2 or kg), so the import does not estimate it
    (fixups/rotors.py skips a joint that has one)."""
    armatures = getattr(draft.source, "armatures", {})
    back = {new: old for old, new in draft.renames.get("joints", {}).items()}
    for joint in draft.spec.get("joints", []):
        value = armatures.get(back.get(joint["name"], joint["name"]))
        if value is not None and "armature" not in joint:
            joint["armature"] = value
            draft.changed()


EDITS = (carry_servos, carry_armatures)
AFTER = (mark_falling,)
