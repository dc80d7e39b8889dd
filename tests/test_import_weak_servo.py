"""A servo that cannot hold home against gravity wherever the joint stands (issue 32, class
6c): a vertical lift carrying 10 kg on a 10 N effort. No home the search can choose holds,
so the import estimates a servo that does (twice the static load), says so on one line and
lists it; the kit's hold checks then agree with the report. An effort that holds is kept."""

from __future__ import annotations

import yaml

from simkit.importer import import_robot
from urdf_parts import link, write

LIFT = (
    '<joint name="lift" type="prismatic"><parent link="base"/><child link="carriage"/>'
    '<origin xyz="0 0 0.3"/><axis xyz="0 0 1"/>'
    '<limit lower="0" upper="0.2" effort="{effort}" velocity="0.2"/></joint>'
)


def _import(tmp_path, effort: str):
    body = (link("base"), link("carriage", mass="10"), LIFT.format(effort=effort))
    done = import_robot(write(tmp_path, "lift", *body), tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    return done, spec, next(j for j in spec["joints"] if j["name"] == "lift")


def test_a_servo_that_cannot_hold_home_anywhere_is_estimated(tmp_path):
    from simkit.pipeline import build

    done, spec, lift = _import(tmp_path, "10")
    assert lift["effort_peak"] == 197.0  # 2 x 10 kg x 9.81 m/s^2, three digits rounded up
    assert "effort_peak" in lift["estimated"]
    said = [line for line in done.lines if "cannot hold home" in line]
    assert len(said) == 1 and "joint[lift]" in said[0] and "effort 10 " in said[0], said
    assert "joints.lift.effort_peak" in {d["what"] for d in spec["source_differences"]}
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert any(f.check.startswith("hold") and f.ok for f in result.findings)


def test_an_effort_that_holds_is_kept(tmp_path):
    _, _, lift = _import(tmp_path, "500")
    assert lift["effort_peak"] == 500.0 and "effort_peak" not in lift.get("estimated", [])
