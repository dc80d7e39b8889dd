"""Collision-only "safety volume" links get no solid's mass (issue 32, class 6a): in a URDF
without inertials whose links are drawn, a link with only a collision cylinder about an arm
link is a safety volume, not a body, so it gets the placeholder speck instead of 34 kg of
aluminium; where no link has a visual, the collision geometry still gives the masses."""

from __future__ import annotations

import yaml

from simkit.importer import import_robot
from urdf_parts import joint, write

BOX = '<geometry><box size="0.05 0.05 0.2"/></geometry>'
CAPSULE = '<geometry><cylinder radius="0.1" length="0.4"/></geometry>'


def _bare(name: str, visual: bool = True) -> str:
    """A link without an inertial: a drawn box, or a collision cylinder only."""
    if visual:
        return f'<link name="{name}"><visual>{BOX}</visual><collision>{BOX}</collision></link>'
    return f'<link name="{name}"><collision>{CAPSULE}</collision></link>'


def _masses(tmp_path, *body: str) -> tuple[dict[str, float], str]:
    done = import_robot(write(tmp_path, "guarded", *body), tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    return {link["name"]: link["mass"] for link in spec["links"]}, "\n".join(done.lines)


def test_a_safety_volume_beside_drawn_links_gets_no_mass(tmp_path):
    from simkit.pipeline import build

    masses, lines = _masses(
        tmp_path,
        _bare("base"),
        _bare("arm"),
        _bare("arm_guard", visual=False),
        joint("shoulder", "base", "arm"),
        joint("guard", "arm", "arm_guard"),
    )
    assert masses["arm"] > 0.5  # 0.0005 m^3 at the default 1400 kg/m^3: 0.7 kg
    assert masses["arm_guard"] == 0.001  # not 1400 kg/m^3 x 0.0126 m^3 = 17.6 kg
    assert "link[arm_guard]: changed: no visual" in lines and "no mass from it" in lines
    result = build(str(tmp_path / "out" / "guarded.yaml"), tmp_path / "kits")
    assert any(f.check == "source.links" and f.ok for f in result.findings)


def test_without_any_visual_the_collision_geometry_gives_the_masses(tmp_path):
    masses, _ = _masses(
        tmp_path,
        _bare("base", visual=False),
        _bare("arm", visual=False),
        joint("shoulder", "base", "arm"),
    )
    assert masses["arm"] > 15.0  # the only solid there is: 0.0126 m^3 at 1400 kg/m^3
