"""A USD joint's damping, friction loss and armature (MjcPhysics `mjc:damping`,
`mjc:frictionloss`, `mjc:armature`; PhysX `physxJointAxis:angular:armature`) come back as the
spec's `damping`, `friction` and `armature`, not estimated; what the read `Physics` variant
lacks is taken from the stage's other variants (importer/formats/usd/dynamics.py), and the
source proof's own reader (check/source/usd/dynamics.py) reads the same values."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from simkit.importer import import_robot
from simkit.importer.read.options import ReadOptions
from usd_stages import BASE_AND_ARM, stage_text

pytest.importorskip("pxr")

#: a one-joint arm: `base` bolted to the world, `arm` on a revolute joint about Z; OWN is the
#: joint's own attribute lines, VARIANTS the `Physics` variant set's (or nothing)
HINGE = """    def PhysicsRevoluteJoint "hinge"
    {{
        rel physics:body0 = </bot/base>
        rel physics:body1 = </bot/arm>
        point3f physics:localPos0 = (0, 0, 0.5)
        uniform token physics:axis = "Z"
        float physics:lowerLimit = -90
        float physics:upperLimit = 90
        float physics:effort = 20
        {own}
    }}
    {variants}
"""

MJC = """double mjc:damping = 0.3
        double mjc:frictionloss = 0.05
        double mjc:armature = 0.02"""

#: a `physx` variant (default) with the armature only, a `mujoco` one with all three
VARIANTS = """variantSet "Physics" = {
        "mujoco" {
            over "hinge" {
                double mjc:damping = 0.3
                double mjc:frictionloss = 0.05
                double mjc:armature = 0.02
            }
        }
        "physx" {
            over "hinge" {
                float physxJointAxis:angular:armature = 0.0102825
            }
        }
    }"""
SELECT = """variants = { string Physics = "physx" }
    prepend variantSets = "Physics\""""


def _usda(tmp_path: Path, own: str = "", variants: bool = False, meters: float = 1.0) -> Path:
    usda = tmp_path / "bot.usda"
    hinge = HINGE.format(own=own, variants=VARIANTS if variants else "")
    usda.write_text(stage_text(BASE_AND_ARM + hinge, meters, SELECT if variants else ""))
    return usda


def _hinge(usda: Path, out: Path, variant: str | None = None) -> dict:
    done = import_robot(usda, out, reading=ReadOptions(variant=variant))
    joints = {j["name"]: j for j in yaml.safe_load(done.spec_path.read_text())["joints"]}
    return joints["hinge"]


def test_mjc_attributes_are_the_spec_values(tmp_path) -> None:
    hinge = _hinge(_usda(tmp_path, MJC), tmp_path / "out")
    assert (hinge["damping"], hinge["friction"], hinge["armature"]) == (0.3, 0.05, 0.02)
    assert "armature" not in hinge.get("estimated", [])


def test_without_them_none_and_armature_estimated(tmp_path) -> None:
    hinge = _hinge(_usda(tmp_path), tmp_path / "out")
    assert "damping" not in hinge and "friction" not in hinge
    assert "armature" in hinge["estimated"]


def test_stage_units(tmp_path) -> None:
    """A centimetre stage: N m s/rad, N m and kg m^2 scale by metres squared."""
    hinge = _hinge(_usda(tmp_path, MJC, meters=0.01), tmp_path / "out")
    assert hinge["damping"] == pytest.approx(0.3e-4)
    assert hinge["friction"] == pytest.approx(0.05e-4)
    assert hinge["armature"] == pytest.approx(0.02e-4)


def test_physx_armature_and_other_variant_fill_the_gaps(tmp_path) -> None:
    """The default `physx` variant gives the armature (its own, float32 as written); damping
    and friction come from the `mujoco` variant; read with `mujoco`, its armature wins."""
    usda = _usda(tmp_path, variants=True)
    hinge = _hinge(usda, tmp_path / "a")
    assert (hinge["damping"], hinge["friction"], hinge["armature"]) == (0.3, 0.05, 0.0102825)
    hinge = _hinge(usda, tmp_path / "b", variant="mujoco")
    assert (hinge["damping"], hinge["friction"], hinge["armature"]) == (0.3, 0.05, 0.02)


def test_source_proof_reads_the_same(tmp_path) -> None:
    """The proof's own reader (no importer code) gives the import's values."""
    from pxr import Usd

    from simkit.check.source.usd import dynamics

    stage = Usd.Stage.Open(str(_usda(tmp_path, variants=True)), Usd.Stage.LoadAll)
    joint = stage.GetPrimAtPath("/bot/hinge")
    found = dynamics.of_joint(joint, "revolute", 1.0, 1.0, dynamics.others(stage, None))
    assert found == {"damping": 0.3, "friction": 0.05, "armature": 0.0102825}
