"""A seed kit's own USD (its entry point, default physx variant) imports back to the kit's
robot (issue 39): the imported kit passes its checks, its `source` findings (the USD proof,
check/source/usd/) pass, and its URDF equals the original kit's URDF within the source
check's tolerances (masses, CoMs, inertias, joint origins, axes, types and limits, efforts
included: the USD carries the URDF's effort limit as `simkit:effortLimit`, apart from the
drive's `maxForce`, the servo's 56.4 N m), and its joints' `<dynamics>` and armature equal the
original's (MjcPhysics damping and friction loss from the `mujoco` variant, PhysX's armature).
"""

from __future__ import annotations

import json

import pytest

from simkit.check.source.shared import Allowed
from simkit.check.source.urdf import compare_robots, load_urdf
from simkit.importer import import_robot
from simkit.pipeline import build

pytestmark = pytest.mark.slow


def test_ecn_2r_round_trip(kit_factory, tmp_path) -> None:
    original = kit_factory("ecn_2r").kit_dir
    done = import_robot(original / "usd" / "ecn_2r.usda", tmp_path / "spec")
    result = build(str(done.spec_path), tmp_path / "kits")
    assert all(f.ok for f in result.findings), [str(f) for f in result.findings if not f.ok]
    source = [f for f in result.findings if f.check.startswith("source.")]
    assert {f.check for f in source} >= {"source.joints", "source.links", "source.fk"}
    findings = compare_robots(
        load_urdf(original / "urdf" / "ecn_2r.urdf"),
        load_urdf(result.kit_dir / "urdf" / "ecn_2r.urdf"),
        Allowed(),
    )
    assert [f.detail for f in findings if not f.ok] == []
    assert _dynamics(original) == _dynamics(result.kit_dir)


def _dynamics(kit) -> dict:
    """Joint name -> (URDF damping, friction, robot.json armature)."""
    doc = json.loads((kit / "robot.json").read_text())
    armatures = {j["name"]: j.get("armature") for j in doc["joints"]}
    out = {}
    for joint in load_urdf(kit / "urdf" / "ecn_2r.urdf").joints:
        d = joint.dynamics
        values = (0.0, 0.0) if d is None else (float(d.damping or 0), float(d.friction or 0))
        out[joint.name] = (*values, armatures.get(joint.name))
    return out
