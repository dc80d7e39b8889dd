"""Sentinel limits (issue 32, class 6b): `effort="-1"` and `velocity="-1"` mean "no limit".
They are read as unspecified: estimated, listed in `source_differences`, reported; never
their absolute value (1 N m, 1 rad/s), which the source check would then find unlisted."""

from __future__ import annotations

from pathlib import Path

import yaml

from simkit.importer import import_robot
from urdf_parts import joint, link, write


def _import(tmp_path: Path, effort: str, velocity: str):
    limit = f'lower="-1" upper="1" effort="{effort}" velocity="{velocity}"'
    body = (
        link("base", mass="2"),
        link("arm", mass="2"),
        joint("hinge", "base", "arm", limit=limit),
    )
    done = import_robot(write(tmp_path, "s", *body), tmp_path / "out")
    return done, yaml.safe_load(done.spec_path.read_text())


def test_negative_effort_and_velocity_are_no_limit(tmp_path):
    from simkit.pipeline import build

    done, spec = _import(tmp_path, "-1", "-1")
    joint = next(j for j in spec["joints"] if j["name"] == "hinge")
    assert joint["max_velocity"] == 3.0  # the estimate for a revolute joint, not |-1|
    assert joint["effort_peak"] > 1.0  # twice the static load of 2 kg, not |-1|
    assert {"max_velocity", "effort_peak"} <= set(joint["estimated"])
    listed = {d["what"] for d in spec["source_differences"]}
    assert {"joints.hinge.max_velocity", "joints.hinge.effort_peak"} <= listed
    lines = "\n".join(done.lines)
    assert "velocity -1 is a placeholder: 3" in lines and "effort -1 is a placeholder" in lines
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert any(f.check == "source.joints" and f.ok for f in result.findings)


def test_positive_limits_are_kept(tmp_path):
    _, spec = _import(tmp_path, "7", "1.5")
    joint = next(j for j in spec["joints"] if j["name"] == "hinge")
    assert (joint["effort_peak"], joint["max_velocity"]) == (7.0, 1.5)
    assert not {"max_velocity", "effort_peak"} & set(joint.get("estimated", []))
