"""A user's spec mistakes: one line naming file, line and field; non-zero exit; no traceback;
no output folder left behind."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from simkit.errors import SpecError
from simkit.spec.load import load_yaml
from simkit.spec.validate import load_spec

REPO = Path(__file__).resolve().parents[1]
GOOD = (REPO / "robots" / "rosie_1000.yaml").read_text()


def _variant(tmp_path: Path, old: str, new: str, count: int = 1) -> Path:
    assert old in GOOD, old
    path = tmp_path / "bad.yaml"
    path.write_text(GOOD.replace(old, new, count))
    return path


def _line_of(path: Path, needle: str) -> int:
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        if needle in line:
            return number
    raise AssertionError(needle)


CASES = [
    (
        "negative mass",
        "    mass: 7.2\n",
        "    mass: -7.2\n",
        "mass: -7.2",
        "links[1].mass",
        "mass must be > 0",
    ),
    (
        "lower > upper",
        "    lower_deg: -135\n",
        "    lower_deg: 170\n",
        "lower_deg: 170",
        "joints[2].lower_deg",
        "greater than upper",
    ),
    (
        "unknown parent",
        "    parent: link_4\n",
        "    parent: link_44\n",
        "parent: link_44",
        "joints[5].parent",
        "unknown parent link 'link_44'",
    ),
    (
        "inertia not positive definite",
        "    mass: 2.9\n",
        "    mass: 2.9\n    com: [0, 0, 0]\n    inertia: {ixx: 0.01, iyy: 0.01, izz: -0.01}\n",
        "inertia: {ixx",
        "links[5].inertia",
        "not positive definite",
    ),
    (
        "inertia breaks triangle inequality",
        "    mass: 2.9\n",
        "    mass: 2.9\n    com: [0, 0, 0]\n    inertia: {ixx: 0.001, iyy: 0.001, izz: 0.01}\n",
        "inertia: {ixx",
        "links[5].inertia",
        "triangle inequality",
    ),
    (
        "unknown field",
        "    material: flange_steel\n",
        "    material: flange_steel\n    colour: red\n",
        "colour: red",
        "links[6].colour",
        "unknown field",
    ),
    (
        "malformed YAML",
        "  - name: J3\n",
        "  - name: J3\n   bad: [1, 2\n",
        "bad: [1, 2",
        "<yaml>",
        "malformed YAML",
    ),
    (
        "unknown drive field",
        "gear_ratio: 121, estimated",
        "gear_ratio: 121, gear: 3, estimated",
        "gear: 3",
        "joints[1].drive.gear",
        "unknown field",
    ),
    (
        "unknown field in a drive's estimated list",
        "gear_ratio: 121, estimated: [motor_peak_torque,",
        "gear_ratio: 121, estimated: [motor_peak,",
        "estimated: [motor_peak,",
        "joints[1].drive.estimated[0]",
        "'motor_peak' is not a field of a drive",
    ),
    (
        "pose in radians and degrees",
        "  home: [0, 0, 0, 0, 0, 0]\n",
        "  home: [0, 0, 0, 0, 0, 0]\nposes:\n  home: [0, 0, 0, 0, 0, 0.1]\n",
        "home: [0, 0, 0, 0, 0, 0]",
        "poses_deg.home",
        "given in both poses and poses_deg",
    ),
    (
        "wrong type",
        "    mass: 7.2\n",
        "    mass: heavy\n",
        "mass: heavy",
        "links[1].mass",
        "valid number",
    ),
    (
        "zero axis",
        "    axis: [0, 0, 1]\n",
        "    axis: [0, 0, 0]\n",
        "axis: [0, 0, 0]",
        "joints[1].axis",
        "axis must not be zero",
    ),
    (
        "continuous above peak",
        "    effort_continuous: 150\n",
        "    effort_continuous: 400\n",
        "effort_continuous: 400",
        "joints[1].effort_continuous",
        "greater than effort_peak",
    ),
    (
        "pose outside limits",
        "  work: [0, 30, 30, 0, -60, 0]",
        "  work: [0, 300, 30, 0, -60, 0]",
        "work: [0, 300",
        "poses_deg.work[1]",
        "outside its limits",
    ),
    (
        "missing mesh file",
        "{shape: box, size: [0.050, 0.080, 0.060], xyz: [-0.105, 0, -0.120]}",
        "{shape: mesh, file: no_such_mesh.stl}",
        "no_such_mesh.stl",
        "links[0].solid[3].file",
        "mesh file not found: no_such_mesh.stl",
    ),
]


@pytest.mark.parametrize(
    ("label", "old", "new", "needle", "field", "message"), CASES, ids=[c[0] for c in CASES]
)
def test_library_reports_file_line_field(tmp_path, label, old, new, needle, field, message):
    path = _variant(tmp_path, old, new)
    with pytest.raises(SpecError) as info:
        load_spec(path)
    err = info.value
    assert err.file == str(path)
    assert err.field == field
    assert message in err.message
    expected_line = _line_of(path, needle)
    # malformed YAML is reported where the parser notices it: at or just after the bad line
    assert err.line is not None and expected_line <= err.line <= expected_line + 1


@pytest.mark.parametrize(
    "label",
    [
        "negative mass",
        "lower > upper",
        "unknown parent",
        "inertia not positive definite",
        "malformed YAML",
        "pose outside limits",
        "missing mesh file",
    ],
)
@pytest.mark.slow
def test_cli_one_line_no_traceback_no_output(tmp_path, label):
    case = next(c for c in CASES if c[0] == label)
    path = _variant(tmp_path, case[1], case[2])
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "simkit.cli", "build", str(path), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode != 0
    lines = [line for line in proc.stderr.splitlines() if line.strip() and not line.startswith("[")]
    assert len(lines) == 1, proc.stderr
    assert "Traceback" not in proc.stderr + proc.stdout
    assert f"{path}:" in lines[0] and case[4] in lines[0]
    assert not any(out.glob("*_description")) and not any(out.glob("*.zip"))


@pytest.mark.slow
def test_cli_unknown_robot_and_missing_file(tmp_path):
    for target in ("no_such_robot", str(tmp_path / "missing.yaml")):
        proc = subprocess.run(
            [sys.executable, "-m", "simkit.cli", "build", target, "--out", str(tmp_path)],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert proc.returncode != 0
        assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
        assert "Traceback" not in proc.stderr


def test_yaml_line_map_points_at_keys(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text("a: 1\nlist:\n  - x: 2\n    y: 3\n")
    doc = load_yaml(path)
    assert doc.lines[("a",)] == 1
    assert doc.lines[("list", 0, "y")] == 4
    assert doc.line_of(("list", 0, "missing")) == 3


@settings(max_examples=40, deadline=None)
@given(mass=st.floats(min_value=-1e3, max_value=1e3, allow_nan=False))
def test_mass_sign_property(tmp_path_factory, mass):
    path = tmp_path_factory.mktemp("m") / "s.yaml"
    path.write_text(GOOD.replace("    mass: 7.2\n", f"    mass: {mass!r}\n", 1))
    if mass >= 1e-4:  # the plausibility floor (spec_bounds.FIELD_BOUNDS)
        spec, _ = load_spec(path)
        assert spec.links[1].mass == mass
    elif mass > 0:
        with pytest.raises(SpecError, match="too small to simulate"):
            load_spec(path)
    else:
        with pytest.raises(SpecError, match="mass must be > 0"):
            load_spec(path)
