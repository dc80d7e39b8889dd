"""Hostile specs (issue 13): every class of input an adversarial user can write ends in one
`FILE:LINE: field: message` line (or `simkit: error: ...`) and a non-zero exit, never a
traceback, a hang or a file outside --out."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from simkit.errors import SpecError
from simkit.spec.validate import load_spec

REPO = Path(__file__).resolve().parents[1]
SPEC = REPO / "tests" / "specs" / "planar_2r.yaml"
GOOD = SPEC.read_text()
ONE_LINE = re.compile(r"^[^\n]+:\d+: [^\n]+: [^\n]+$")


def _spec(tmp_path: Path, text: str, name: str = "s.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _edit(old: str, new: str) -> str:
    assert old in GOOD, old
    return GOOD.replace(old, new, 1)


def _refused(tmp_path: Path, text: str, field: str, message: str) -> SpecError:
    with pytest.raises(SpecError) as info:
        load_spec(_spec(tmp_path, text))
    err = info.value
    assert all(ONE_LINE.match(line) for line in str(err).splitlines()), str(err)
    assert err.line is not None and err.field == field and message in err.message, str(err)
    return err


NAMES = [
    (
        "path",
        "  - name: base_link\n",
        "  - name: ../../../../../EVIL\n",
        "links[0].name",
        "invalid",
    ),
    ("quote", "  - name: joint_2\n", "  - name: 'j\"2'\n", "joints[2].name", "invalid"),
    ("empty", "  - name: joint_2\n", "  - name: ''\n", "joints[2].name", "empty"),
    ("control", "  - name: joint_2\n", '  - name: "j\\x012"\n', "joints[2].name", "invalid"),
    ("dash", "  - name: joint_2\n", "  - name: joint-2\n", "joints[2].name", "invalid"),
    ("long", "  - name: joint_2\n", f"  - name: j{'x' * 80}\n", "joints[2].name", "at most"),
    ("robot", "name: planar_2r\n", f"name: r{'x' * 299}\n", "name", "at most"),
    (
        "frame_joint",
        "  - name: base_joint\n",
        "  - name: tool0_joint\n",
        "joints[0].name",
        "generates",
    ),
    (
        "piece",
        "  - name: joint_2\n",
        "  - name: link_2_collision_00\n",
        "joints[2].name",
        "generates",
    ),
    ("case", "  - name: joint_2\n", "  - name: LINK_1\n", "joints[2].name", "only by case"),
    (
        "reserved",
        "  - name: base_joint\n",
        "  - name: virtual_joint\n",
        "joints[0].name",
        "writes itself",
    ),
    ("pose", "  work: [30, 30]\n", "  'wo rk': [30, 30]\n", "poses_deg.wo rk", "invalid"),
]


@pytest.mark.parametrize("case", NAMES, ids=[c[0] for c in NAMES])
def test_names_follow_one_grammar(tmp_path, case):
    _, old, new, field, message = case
    _refused(tmp_path, _edit(old, new), field, message)


def test_uppercase_names_are_valid(tmp_path):
    text = GOOD.replace("joint_1", "J1").replace("joint_2", "J2")
    spec, _ = load_spec(_spec(tmp_path, text))
    assert [j.name for j in spec.joints][1:] == ["J1", "J2"]


YAML = [
    ("merge", "links:\n", "anchors: &d {mass: 1}\nlinks:\n", "anchors", None),
    (
        "merge_key",
        "  - name: link_1\n    mass: 1.0\n",
        "  - name: link_1\n    <<: {mass: 1.0}\n",
        "links[1]",
        "merge keys",
    ),
    ("tag", "title: Planar 2R\n", "title: !!python/object:os.system id\n", "title", "tag"),
    ("custom_tag", "title: Planar 2R\n", "title: !foo x\n", "title", "tag"),
    ("nul", "title: Planar 2R\n", 'title: "P\x00"\n', "<yaml>", "control character"),
    ("recursive", "title: Planar 2R\n", "title: &a [*a]\n", "title[0]", "recursive alias"),
    ("deep", "title: Planar 2R\n", "title: " + "[" * 100 + "]" * 100 + "\n", "title", "nested"),
]


@pytest.mark.parametrize("case", YAML, ids=[c[0] for c in YAML])
def test_yaml_features_are_refused_in_one_line(tmp_path, case):
    _, old, new, field, message = case
    if message is None:  # an unknown top-level key: the schema refuses it
        _refused(tmp_path, _edit(old, new), field, "unknown field")
        return
    with pytest.raises(SpecError) as info:
        load_spec(_spec(tmp_path, _edit(old, new)))
    assert "\n" not in str(info.value) and message in info.value.message, str(info.value)
    assert info.value.field.startswith(field.split("[")[0]), str(info.value)


BOUNDS = [
    ("limit", "    lower_deg: -170\n", "    lower_deg: -1.0e9\n", "joints[1].lower_deg", "turns"),
    (
        "limit36000",
        "    upper_deg: 170\n",
        "    upper_deg: 36000\n",
        "joints[1].upper_deg",
        "turns",
    ),
    ("mass", "    mass: 2.0\n", "    mass: 1.0e12\n", "links[0].mass", "at most"),
    ("tiny", "radius: 0.05,", "radius: 1.0e-9,", "links[0].solid[0].radius", "too small"),
    ("length", "to: [0.3, 0, 0]", "to: [3.0e8, 0, 0]", "links[1].solid[0].to[0]", "at most"),
    (
        "speed",
        "    max_velocity_deg_s: 180\n",
        "    max_velocity_deg_s: 1.0e9\n",
        "joints[1].max_velocity_deg_s",
        "at most",
    ),
    (
        "effort",
        "    effort_peak: 20\n",
        "    effort_peak: 1.0e15\n",
        "joints[1].effort_peak",
        "at most",
    ),
    ("title", "title: Planar 2R\n", f"title: {'x' * 5000}\n", "title", "at most 200"),
    ("title_lines", "title: Planar 2R\n", 'title: "a\\nb"\n', "title", "control"),
    ("seed", "seed: 1\n", "seed: 100000000000000000000\n", "seed", "at most"),
    # validated, then numpy refused it in the build: "expected non-negative integer" (fuzz)
    ("seed_negative", "seed: 1\n", "seed: -1\n", "seed", "greater than or equal to 0"),
]


@pytest.mark.parametrize("case", BOUNDS, ids=[c[0] for c in BOUNDS])
def test_absurd_magnitudes_are_refused(tmp_path, case):
    _, old, new, field, message = case
    _refused(tmp_path, _edit(old, new), field, message)


def test_escape_filters_keep_each_language_intact():
    from simkit.emit.escape import comment, py, pydoc, xml, yaml_scalar
    from simkit.kitio.xmlwriter import comment_text

    hostile = 'R"""\nimport os; os.system(\'id\')\n"""\\ \x01 -- on'
    doc = ast.parse(f'"""{pydoc(hostile)}"""\nX = {py(hostile)}\n')
    assert ast.get_docstring(doc, clean=False) == hostile
    assert len(doc.body) == 2 and ast.literal_eval(doc.body[1].value) == hostile
    assert "\n" not in comment(hostile)
    for word in ("on", "null", "a: b", "- x", "#x", hostile):
        assert yaml.safe_load(f"k: [{yaml_scalar(word)}]") == {"k": [word]}
    import xml.etree.ElementTree as ET

    root = ET.fromstring(
        f'<a b="{xml(hostile.replace(chr(1), ""))}"><!-- {comment_text("my--robot-")} --></a>'
    )
    assert root.get("b") == hostile.replace("\x01", "").replace("\n", " ")


def _cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "simkit.cli", *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=cwd,
    )


def _one_line_failure(proc: subprocess.CompletedProcess) -> str:
    assert proc.returncode != 0, proc.stdout
    assert "Traceback" not in proc.stderr + proc.stdout, proc.stderr
    lines = [line for line in proc.stderr.splitlines() if not line.startswith("[")]
    lines = [line for line in lines if not line.startswith("simkit: warning:")]
    assert lines and lines[0].startswith("simkit: error: "), proc.stderr
    assert all(ONE_LINE.match(line) for line in lines[1:]), proc.stderr  # one per problem
    return lines[0]


def test_unreadable_mesh_names_its_line(tmp_path):
    from simkit.kitio.cache import Cache
    from simkit.pipeline import model_from_spec

    (tmp_path / "bad.stl").write_bytes(b"\x00\x01 not a mesh" * 10)
    text = _edit(
        "      - {shape: capsule, radius: 0.015, from: [0, 0, 0], to: [0.2, 0, 0]}\n",
        "      - {shape: mesh, file: bad.stl}\n",
    )
    path = _spec(tmp_path, text)
    with pytest.raises(SpecError) as info:
        model_from_spec(str(path), cache=Cache.disabled())
    err = info.value
    assert err.file == str(path) and err.field == "links[2].solid[0].file", str(err)
    assert err.line == text.splitlines().index("      - {shape: mesh, file: bad.stl}") + 1


@pytest.mark.slow
def test_build_cli_refusals_are_one_line(tmp_path):
    """--out on a file, a spec named my--robot.yaml, and a hostile title, through the CLI."""
    a_file = tmp_path / "file"
    a_file.write_text("x")
    line = _one_line_failure(_cli("build", str(SPEC), "--out", str(a_file)))
    assert "is a file" in line
    line = _one_line_failure(_cli("build", str(SPEC), "--out", str(a_file / "sub")))
    assert "cannot create" in line
    # a file name XML forbids in a comment, and a title that is Python, YAML and XML syntax
    title = 'R\\"\\"\\" --> <x/> & \\\\ # on: [1'
    spec = _spec(tmp_path, _edit("title: Planar 2R\n", f'title: "{title}"\n'), "my--robot.yaml")
    out = tmp_path / "out"
    proc = _cli("build", str(spec), "--out", str(out), "-q")
    assert proc.returncode == 0, proc.stderr
    kit = out / "planar_2r_description"
    for path in kit.rglob("*.py"):
        tree = ast.parse(path.read_bytes())
        assert 'R"""' in (ast.get_docstring(tree, clean=False) or ""), path
    for path in [*kit.rglob("*.yaml"), *kit.rglob("*.rviz")]:
        yaml.safe_load(path.read_bytes())
    assert _cli("check", str(kit)).returncode == 0
    outside = [p for p in tmp_path.rglob("*") if out not in p.parents and p != out]
    assert sorted(p.name for p in outside) == ["file", "my--robot.yaml"]


def test_deep_derive_errors_carry_file_and_line(tmp_path):
    """An error a derive step raises with only a field (freefall.py: `freefall.pose`) is
    located in the spec; so is a solid that subtract empties."""
    from simkit.kitio.cache import Cache
    from simkit.pipeline import model_from_spec
    from simkit.spec.load import load_yaml
    from simkit.spec.locate import locate

    text = GOOD + "freefall:\n  pose: work\n"
    path = _spec(tmp_path, text)
    spec, doc = load_spec(path)
    deep = SpecError("robots/x.yaml", None, "freefall.pose", "released at 'work', ...")
    err = locate(deep, load_yaml(path), spec, tmp_path)
    assert (err.file, err.line, err.field) == (str(path), len(text.splitlines()), "freefall.pose")
    assert doc.line_of(("freefall", "pose")) == err.line

    capsule = "      - {shape: capsule, radius: 0.015, from: [0, 0, 0], to: [0.2, 0, 0]}\n"
    text = _edit(capsule, capsule + "      - {shape: box, size: [1, 1, 1], subtract: true}\n")
    path = _spec(tmp_path, text, "empty.yaml")
    with pytest.raises(SpecError) as info:
        model_from_spec(str(path), cache=Cache.disabled(), jobs=1)
    err = info.value
    assert (err.file, err.field) == (str(path), "links[2].solid") and err.line, str(err)
    assert "no positive volume" in err.message


def test_link_without_solid_or_inertia_is_refused(tmp_path):
    """Found by scripts/fuzz_specs.py: `solid: []` with collision primitives crashed derive."""
    text = _edit(
        "      - {shape: cylinder, radius: 0.05, from: [0, 0, 0], to: [0, 0, 0.05]}\n", ""
    ).replace(
        "    solid:\n    collision: primitives\n", "    solid: []\n    collision: primitives\n", 1
    )
    _refused(tmp_path, text, "links[0].solid", "needs inertia and com")


# --- issue 24: numbers and keys that crashed, a pedestal beside the arm, stiff free fall ---

HUGE = [
    ("seed_400", "seed: 1\n", f"seed: {'9' * 400}\n", "seed", "400 digits"),
    ("mass_400", "    mass: 2.0\n", f"    mass: {'9' * 400}\n", "links[0].mass", "400 digits"),
    ("pose_5000", "  home: [0, 0]\n", f"  home: [{'1' * 5000}, 0]\n", "poses_deg.home[0]", "5000"),
]


@pytest.mark.parametrize("case", HUGE, ids=[c[0] for c in HUGE])
def test_a_huge_integer_is_one_line(tmp_path, case):
    """A 400-digit seed raised OverflowError (float()); 5000 digits hit Python's int limit."""
    _, old, new, field, message = case
    _refused(tmp_path, _edit(old, new), field, message)


@pytest.mark.parametrize(
    "old, new, field",
    [
        ("    mass: 2.0\n", '    mass: 2.0\n    "ab\\ncd": 1\n', "links[0]"),
        ("seed: 1\n", 'seed: 1\n"x\\ny": 2\n', "<root>"),
        ("seed: 1\n", 'seed: 1\n"x\\ty": 2\n', "<root>"),
    ],
    ids=["link_key", "root_key", "tab_key"],
)
def test_a_key_with_an_escaped_newline_is_one_line(tmp_path, old, new, field):
    err = _refused(tmp_path, _edit(old, new), field, "not one line of printable text")
    assert "\n" not in str(err)


PEDESTAL = """  - name: pedestal
    mass: 1.0
    solid:
      - {shape: box, size: [0.1, 0.1, 0.1], xyz: [0.5, 0, 0.05]}
    collision: primitives
  - name: pan
    mass: 0.5
    solid:
      - {shape: box, size: [0.05, 0.05, 0.05], xyz: [0, 0, 0.025]}
    collision: primitives
"""
PAN_JOINTS = """  - name: pan_joint
    parent: pedestal
    child: pan
    xyz: [0.5, 0, 0.1]
    axis: [0, 0, 1]
    lower_deg: -90
    upper_deg: 90
    effort_peak: 5
    max_velocity_deg_s: 90
  - name: pedestal_joint
    type: fixed
    parent: world
    child: pedestal
"""


@pytest.mark.slow
def test_a_pedestal_with_a_joint_listed_first_builds(tmp_path):
    """A fixed pedestal off `world` carrying a pan joint listed before the arm's joints: the
    SRDF emitter raised KeyError 'world' (its group started at the pan joint's parent, off
    the tool's chain). The base frame and the group now start on the tool's chain."""
    from simkit.pipeline import build

    text = GOOD.replace("root: base_footprint", "root: world")
    text = text.replace("parent: base_footprint", "parent: world")
    text = text.replace("links:\n", "links:\n" + PEDESTAL, 1)
    text = text.replace("joints:\n", "joints:\n" + PAN_JOINTS, 1)
    for pose in ("home: [0, 0]", "work: [30, 30]", "stretched: [0, 0]"):
        text = text.replace(pose, pose.replace("[", "[0, "))
    result = build(str(_spec(tmp_path, text, "planar_2r.yaml")), tmp_path / "out")
    assert all(f.ok for f in result.findings)
    srdf = (result.kit_dir / "srdf" / "planar_2r.srdf").read_text()
    assert '<chain base_link="base_link" tip_link="tool0" />' in srdf
    assert '<joint name="joint_1"' in srdf and '<joint name="pan_joint"' not in srdf


def test_free_fall_integration_has_an_evaluation_budget():
    """The independent integration stops at its budget (joint friction 1e5 N m made it run
    for minutes); the refusal names the limit."""
    import numpy as np

    from simkit.model import rnea
    from simkit.pipeline import model_from_spec

    robot = model_from_spec("ecn_2r")
    q0 = np.asarray(robot.pose(robot.freefall.pose), float)
    times = np.arange(201) * 0.01
    with pytest.raises(rnea.EvaluationBudget, match="more than 50 dynamics evaluations"):
        rnea.integrate(robot, q0, 2.0, times, max_evals=50)


@pytest.mark.slow
def test_joint_friction_1e5_is_refused_in_one_line(tmp_path):
    """ecn_2r with joint friction 1e5 N m: one line naming the budget, in seconds, not
    minutes."""
    import time

    from simkit.simulate.freefall import MAX_EVALS

    text = (REPO / "robots" / "ecn_2r.yaml").read_text()
    assert "    friction: 0.01 " in text
    spec = _spec(
        tmp_path, text.replace("    friction: 0.01 ", "    friction: 100000.0 ", 1), "ecn_2r.yaml"
    )
    start = time.monotonic()
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "simkit.cli",
            "build",
            str(spec),
            "--out",
            str(tmp_path / "o"),
            "-q",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert time.monotonic() - start < 120
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    line = result.stderr.strip()
    assert "\n" not in line and f"budget of {MAX_EVALS} dynamics evaluations" in line, line
    assert not (tmp_path / "o" / "ecn_2r_description").exists()
