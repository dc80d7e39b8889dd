"""`simkit diff` for the USD asset as a composed stage (issue 33), not as layer files.

The kit's `usd/NAME.usda` is an interface layer over payload layers, with a `Physics` variant
set. A reviewer needs to know what a user's stage holds, so both kits' `usd/` files are
composed by pxr in a temporary folder, and each physics variant is compared prim by prim:
type, applied schemas, every attribute's value (numbers within the checks' 1e-6 tolerance)
and every relationship's targets. Mesh arrays (points, indices, normals, extents, primvars)
are left to the STL comparison (`mesh`), as in `scene`. Moving an opinion from one layer to
another is not a change; a different value in the composed stage is.

An old kit whose USD is one file has no variant set: its stage is compared with the variant
the new stage opens with, so a change of layout alone shows only what a user's stage gains
or loses.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from simkit.diff.report import Change
from simkit.diff.scene import USD_MESH_ARRAYS
from simkit.diff.tolerance import PARAM_SI, is_number, leaf_changes
from simkit.kitio import layout

VARIANT_SET = "Physics"
#: provenance, not the robot: the spec's path (robot.json's provenance.spec, which the diff
#: also leaves to its metadata line)
PROVENANCE = {"isaac:source"}
#: rows listed per side before the rest are counted in one row
MAX_ROWS = 60


def is_usd(path: str) -> bool:
    """A file of the USD asset (its layers and thumbnail)."""
    return path.startswith("usd/")


def _plain(value: object) -> object:
    """A pxr value as JSON-like data: numbers, strings, lists."""
    if value is None or isinstance(value, bool | int | float | str):
        return value
    if hasattr(value, "pathString"):
        return value.pathString
    try:
        items = list(value)  # Gf vectors, quaternions' imaginary part, matrices, arrays
    except TypeError:
        return str(value)
    if hasattr(value, "GetReal"):  # a quaternion: real part first
        return [float(value.GetReal()), *[float(v) for v in value.GetImaginary()]]
    return [_plain(v) for v in items] or None  # an empty array is no opinion


def _prims(stage) -> dict[str, dict]:
    """{prim path: {field: value}} of the composed stage, without mesh arrays."""
    out = {}
    for prim in stage.Traverse():
        fields: dict[str, object] = {"type": str(prim.GetTypeName())}
        fields["apiSchemas"] = sorted(str(s) for s in prim.GetAppliedSchemas())
        for attr in prim.GetAttributes():
            name = attr.GetName()
            if name in PROVENANCE or USD_MESH_ARRAYS.fullmatch(f"{name} = []".encode()):
                continue
            value = _plain(attr.Get())
            if value is not None:  # no value or an empty array: no opinion to compare
                fields[name] = value
        for rel in prim.GetRelationships():
            fields[rel.GetName()] = sorted(str(t) for t in rel.GetTargets())
        out[str(prim.GetPath())] = fields
    return out


def _open(files: dict[str, bytes], folder: Path):
    """The composed stage of a kit's `usd/` files written under `folder`, or None."""
    from pxr import Usd

    name = _name(files)
    entry = next((p for p in (layout.usd(name), layout.usd(name, binary=True)) if p in files), None)
    if entry is None:
        return None
    for path, data in files.items():
        if is_usd(path):
            target = folder / path
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
    try:
        return Usd.Stage.Open(str(folder / entry), Usd.Stage.LoadAll)
    except Exception:  # pxr's own error types on a layer it cannot compose
        return None


def _name(files: dict[str, bytes]) -> str:
    import json

    try:
        return str(json.loads(files[layout.ROBOT_JSON])["name"])
    except (KeyError, ValueError, TypeError):
        return ""


def _variants(stage) -> tuple[dict[str, dict[str, dict]], str]:
    """({variant name: prims} for each physics variant, the variant the stage opens with);
    ({"": prims}, "") where there is no variant set."""
    top = stage.GetDefaultPrim()
    variants = top.GetVariantSet(VARIANT_SET) if top and top.IsValid() else None
    names = list(variants.GetVariantNames()) if variants else []
    if not names:
        return {"": _prims(stage)}, ""
    default = variants.GetVariantSelection()
    out = {}
    for name in names:
        with_variant = stage.GetSessionLayer()
        stage.SetEditTarget(with_variant)
        variants.SetVariantSelection(name)
        out[name] = _prims(stage)
    return out, default


def _compare(label: str, old: dict[str, dict], new: dict[str, dict]) -> list[Change]:
    rows = [Change("usd", f"{label}{p}", "removed") for p in old if p not in new]
    rows += [Change("usd", f"{label}{p}", "added") for p in new if p not in old]
    for path in (p for p in new if p in old):
        for field, a, b in leaf_changes(old[path], new[path], PARAM_SI):
            tol = PARAM_SI if is_number(a) or is_number(b) else 0.0
            rows.append(Change("usd", f"{label}{path}", "modified", field, a, b, tolerance=tol))
    if len(rows) > MAX_ROWS:
        more = f"{len(rows) - MAX_ROWS} more"
        rows = [*rows[:MAX_ROWS], Change("usd", f"{label}...", "modified", "...", "-", more)]
    return rows


def stage_changes(old: dict[str, bytes], new: dict[str, bytes]) -> list[Change] | None:
    """Changes between the two kits' composed USD stages, every physics variant; None when
    either side cannot be composed (the caller then compares the files)."""
    with tempfile.TemporaryDirectory(prefix="simkit-diff-usd-") as tmp:
        stages = _open(old, Path(tmp) / "old"), _open(new, Path(tmp) / "new")
        if stages[0] is None or stages[1] is None:
            return None
        (before, old_default), (after, new_default) = _variants(stages[0]), _variants(stages[1])
    if list(before) == [""]:  # a one-file USD is what the new stage opens with
        after = {"": after[new_default]} if new_default else after
    elif list(after) == [""]:
        before = {"": before[old_default]} if old_default else before
    out = []
    for variant in sorted(set(before) | set(after)):
        label = f"{variant}:" if variant else ""
        if variant not in before or variant not in after:
            out.append(Change("usd", f"{label}/", "added" if variant in after else "removed"))
            continue
        out += _compare(label, before[variant], after[variant])
    return out
