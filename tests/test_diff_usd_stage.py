"""`simkit diff` compares the composed USD stage, per physics variant, not the layer files
(issue 33): a layer rewritten with the same opinions is no change; a mass changed in the
physics payload is one row naming the variant, the prim and the attribute."""

from __future__ import annotations

import shutil
from pathlib import Path

from simkit.diff import diff_kits
from simkit.kitio import layout

PHYSICS = Path(layout.usd_payload("ecn_2r", "physics.usda"))


def _copy(kit: Path, tmp_path: Path) -> Path:
    out = tmp_path / kit.name
    shutil.copytree(kit, out)
    return out


def test_a_rewritten_layer_is_no_change(seed_kits, tmp_path):
    """Every USD text layer laid out anew (blank lines: other bytes, the same opinions)."""
    old = seed_kits["ecn_2r"].kit_dir
    new = _copy(old, tmp_path)
    rewritten = 0
    for path in sorted((new / "usd").rglob("*.usda")):
        text = path.read_text()
        if "\n\n" in text:
            path.write_text(text.replace("\n\n", "\n\n\n"))
            rewritten += 1
    assert rewritten
    report = diff_kits(old, new)
    assert not [c for c in report.changes if c.kind == "usd"]
    assert not [p for p in report.changed if p.startswith("usd/")]
    assert [p for p in report.round_off if p.startswith("usd/")]


def test_a_physics_change_is_a_row_per_variant(seed_kits, tmp_path):
    old = seed_kits["ecn_2r"].kit_dir
    new = _copy(old, tmp_path)
    layer = new / PHYSICS
    text = layer.read_text()
    assert text.count("float physics:mass = 7.084761") == 1
    layer.write_text(text.replace("float physics:mass = 7.084761", "float physics:mass = 7.5"))
    report = diff_kits(old, new)
    rows = [c for c in report.changes if c.kind == "usd"]
    assert {(c.name, c.field, c.old, c.new) for c in rows} == {
        (f"{variant}:/ecn_2r/link_1", "physics:mass", 7.084761, 7.5)
        for variant in ("mujoco", "physics", "physx")
    }
    assert str(PHYSICS.as_posix()) in report.changed
