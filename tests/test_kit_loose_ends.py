"""Kit loose ends (issue 38): nothing in a kit points outside it. The kit README names its
sources by the documents' titles (the spec's `sources`), not by file names the kit does not
ship; the ROS launch file carries its own mesh rewrite; robot.json `files` lists every format
the kit holds; examples/mjx_demo.py says that its first call compiles before it goes quiet."""

from __future__ import annotations

import ast
import importlib.util
import json
import re
from pathlib import Path

import pytest

from conftest import SEED_ROBOTS
from simkit.kitio import layout
from simkit.pipeline import build, find_spec
from simkit.spec.validate import load_spec

SPECS = Path(__file__).resolve().parent / "specs"
#: A file name: a word, a dot, an extension (what a README would name a document by).
FILE_NAME = re.compile(r"\b[\w-]+\.(?:txt|pdf|md|html|yaml|urdf|xml|json)\b")
#: Kit folders holding one format each, and the robot.json `files` key that names it.
FORMAT_FOLDERS = {
    "urdf": "urdf",
    "sdf": "sdf",
    "srdf": "srdf",
    "glb": "glb",
    "step": "step",
    "usd": "usd",
}


def _sources_section(readme: str) -> list[str]:
    """The bullets under the README's `## Sources` heading."""
    section = readme.split("\n## Sources\n", 1)[1].split("\n## ", 1)[0]
    return [line[2:] for line in section.splitlines() if line.startswith("- ")]


@pytest.mark.parametrize("name", SEED_ROBOTS)
def test_the_readme_names_its_sources_by_title_not_by_unshipped_files(seed_kits, name):
    files = seed_kits[name].files
    readme = files["README.md"].decode()
    spec, _ = load_spec(find_spec(name)[0])
    bullets = _sources_section(readme)
    assert bullets == list(spec.sources), bullets
    for bullet in bullets:
        named = FILE_NAME.findall(bullet)
        assert all(n in files or any(p.endswith("/" + n) for p in files) for n in named), bullet
    # no shared reference document's file name anywhere in the README
    assert not re.search(r"\b\d{3}_[0-9a-f]{16}\.txt\b", readme), name


@pytest.mark.parametrize("name", SEED_ROBOTS)
def test_the_launch_file_rewrites_every_mesh_itself(seed_kits, name):
    """display.launch.py's own rewrite (its constants, applied as its `robot_description`
    does) turns every mesh of the URDF into a package:// URI of a file the kit ships."""
    files = seed_kits[name].files
    launch = files["launch/display.launch.py"].decode()
    assert "kit page" not in launch and "sed" not in launch
    assert ".replace(RELATIVE_MESHES, PACKAGE_MESHES)" in launch
    consts = {}
    for node in ast.parse(launch).body:
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name):
            target = node.targets[0].id
            if target in ("PACKAGE", "URDF", "RELATIVE_MESHES", "PACKAGE_MESHES"):
                consts[target] = eval(compile(ast.Expression(node.value), "launch", "eval"), consts)
    urdf = (
        files[consts["URDF"]].decode().replace(consts["RELATIVE_MESHES"], consts["PACKAGE_MESHES"])
    )
    meshes = re.findall(r'<mesh filename="([^"]+)"', urdf)
    prefix = f"package://{consts['PACKAGE']}/"
    assert meshes and all(m.startswith(prefix) for m in meshes), meshes[:3]
    assert all(m[len(prefix) :] in files for m in meshes)


@pytest.mark.parametrize("name", SEED_ROBOTS)
def test_robot_json_files_lists_every_format_the_kit_holds(seed_kits, name):
    files = seed_kits[name].files
    listed = json.loads(files["robot.json"])["files"]
    assert all(path in files for path in listed.values()), listed
    folders = {path.split("/", 1)[0] for path in files if "/" in path}
    for folder, key in FORMAT_FOLDERS.items():
        if folder in folders:
            assert key in listed and listed[key].startswith(folder + "/"), (folder, listed)
    assert {"sdf", "srdf", "usd", "usd_asset", "step", "glb", "urdf", "mjcf"} <= set(listed)
    assert listed["usd"] == layout.usd(name) and listed["step"] == layout.step(name)


@pytest.mark.slow
def test_robot_json_files_follows_the_build_options(tmp_path):
    """A binary USD and no STEP: `files` names the .usdc and no STEP (the simulate stage's
    cache is keyed by the staged paths, so a .usda build's robot.json is not reused)."""
    spec = str(SPECS / "planar_2r.yaml")
    text = build(spec, tmp_path / "a", usd_format="usda", remember=False)
    binary = build(spec, tmp_path / "b", usd_format="usdc", step=False, remember=False)
    a = json.loads(text.files["robot.json"])["files"]
    b = json.loads(binary.files["robot.json"])["files"]
    assert a["usd"].endswith(".usda") and "step" in a
    assert b["usd"] == layout.usd("planar_2r", binary=True) and "step" not in b
    assert b["usd"] in binary.files


NEEDS_MJX = pytest.mark.skipif(
    importlib.util.find_spec("mujoco.mjx") is None or importlib.util.find_spec("jax") is None,
    reason="mujoco-mjx and jax not installed",
)


def test_the_mjx_demo_says_the_first_call_compiles_before_making_it(seed_kits):
    script = seed_kits["rosie_600"].files[layout.example("mjx_demo.py")].decode()
    say = script.index('"compiling the rollout: the first call compiles it before it runs')
    first_call = script.index("rollout(batch))")
    assert say < first_call < script.index('print(f"compiled and ran the first rollout in')
    assert re.search(r'COMPILE_CPU = "[^"]*\d[^"]*"', script)  # a figure, not just "a while"
    assert "flush=True" in script[say:first_call]  # shown at once, even through a pipe


@NEEDS_MJX
@pytest.mark.slow
@pytest.mark.xdist_group("mjx_demo")
def test_the_mjx_demo_prints_its_progress_in_order(ecn_2r_mjx_demo):
    done = ecn_2r_mjx_demo  # ecn_2r's demo, run from inside its kit
    assert done.returncode == 0, done.stderr[-2000:]
    lines = done.stdout.splitlines()
    compiling = next(i for i, s in enumerate(lines) if s.startswith("compiling the rollout"))
    compiled = next(i for i, s in enumerate(lines) if s.startswith("compiled and ran the first"))
    assert compiling < compiled and "on a CPU" in lines[compiling], lines
