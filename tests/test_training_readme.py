"""The kit README's training section (issue 41): its MuJoCo Playground and mjlab snippets run
from inside every seed kit, as a user pastes them, and its Isaac Lab snippet is valid Python
(Isaac Sim cannot run here; the config's values are held to the USD by `training.*` checks).
The frameworks live in simkit[train] (CI's training venv); without them the runs skip."""

from __future__ import annotations

import subprocess
import sys

import pytest
from tests.test_kit_readme import BLOCK, TRAINING
from tests.test_training import SEEDS, _require

pytestmark = pytest.mark.slow


def _snippets(kit) -> dict[str, str]:
    """{framework module: snippet} of the README's training section."""
    section = TRAINING.search((kit / "README.md").read_text())
    assert section, "the kit README has a training section"
    found = {}
    for code in BLOCK.findall(section.group(0)):
        for module in ("playground_env", "mjlab_cfg", "isaaclab_cfg"):
            if module in code:
                found[module] = code
    assert sorted(found) == ["isaaclab_cfg", "mjlab_cfg", "playground_env"], found
    return found


@pytest.mark.parametrize("name", SEEDS)
def test_the_isaaclab_snippet_is_python(kit_factory, name):
    code = _snippets(kit_factory(name).kit_dir)["isaaclab_cfg"]
    compile(code, "README.md", "exec")


@pytest.mark.parametrize("framework", ["mujoco_playground", "mjlab"])
@pytest.mark.parametrize("name", SEEDS)
def test_the_framework_snippet_runs_inside_the_kit(kit_factory, name, framework):
    _require(framework)
    kit = kit_factory(name).kit_dir
    module = "playground_env" if framework == "mujoco_playground" else "mjlab_cfg"
    code = _snippets(kit)[module]
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=kit, capture_output=True, text=True, timeout=600
    )
    assert proc.returncode == 0, f"snippet failed:\n{code}\n{proc.stderr[-2000:]}"
