"""Long chains import in near-linear time (issue 24): no refusal below the spec's 10,000
links, no RecursionError, and a spec that validates. Time is measured by
scripts/time_long_chain.py (docs/performance.md); the subprocess timeout only catches hangs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from simkit.importer.fixups import SEARCH_LINKS
from simkit.importer.fixups.rotors import axis_inertias
from simkit.model.dynamics import axis_inertia
from simkit.model.resolve import resolve
from simkit.spec.validate import load_spec

LINK = (
    '<link name="l{k}"><inertial><origin xyz="0.001 0 0.002"/><mass value="1"/>'
    '<inertia ixx="0.001" iyy="0.002" izz="0.003" ixy="0" ixz="0" iyz="0"/></inertial>'
    '<visual><geometry><box size="0.01 0.01 0.01"/></geometry></visual></link>'
)
JOINT = (
    '<joint name="j{k}" type="{kind}"><parent link="l{p}"/><child link="l{k}"/>'
    '<origin xyz="0.003 0 0.01" rpy="0.1 0 0.2"/><axis xyz="{axis}"/>'
    '<limit lower="-1" upper="1" effort="20" velocity="2"/></joint>'
)


def _urdf(path: Path, parents: list[int], kinds: tuple[str, ...] = ("revolute",)) -> Path:
    """Link k (k >= 1) on link parents[k - 1]; joint types and axes cycle through `kinds`."""
    axes = ("1 0 0", "0 1 0", "0 0.6 0.8")
    body = [LINK.format(k=0)]
    for k, p in enumerate(parents, start=1):
        kind, axis = kinds[k % len(kinds)], axes[k % len(axes)]
        body += [LINK.format(k=k), JOINT.format(k=k, p=p, kind=kind, axis=axis)]
    path.write_text(
        '<?xml version="1.0"?>\n<robot name="chain">\n' + "\n".join(body) + "\n</robot>\n"
    )
    return path


@pytest.mark.slow
@pytest.mark.parametrize("base", ["--fixed-base", "--floating-base"])
def test_a_chain_of_2000_links_imports_and_validates(tmp_path, base):
    """Refused at 256 links before; with that cap raised, a RecursionError in serialising
    the MuJoCo model (fixed) or in upright.py's limb walk (floating). The MuJoCo searches are
    skipped above SEARCH_LINKS, one line each."""
    urdf = _urdf(tmp_path / "chain.urdf", list(range(1999)))
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "simkit.cli", "import", str(urdf), "--out", str(out), base]
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=600)  # a hang guard
    assert run.returncode == 0, run.stderr
    assert "Traceback" not in run.stderr
    spec, _doc = load_spec(out / "chain.yaml")
    assert len(spec.links) == 2000 and len(spec.joints) == 2000  # and the base's joint
    skipped = [
        line for line in run.stdout.splitlines() + run.stderr.splitlines() if "skipped" in line
    ]
    assert any(f"2000 links, more than the {SEARCH_LINKS}" in line for line in skipped), run.stdout


def test_summed_axis_inertias_match_the_per_joint_measure(tmp_path):
    """masses.axis_inertias (one pass up the tree) gives dynamics.axis_inertia's value for
    every joint of a branched tree with revolute and prismatic joints, at a random pose."""
    from simkit.importer import import_robot

    parents = [0, 1, 1, 2, 3, 3, 0, 7, 8]
    urdf = _urdf(tmp_path / "tree.urdf", parents, ("revolute", "prismatic", "continuous"))
    done = import_robot(urdf, tmp_path / "out")
    spec, doc = load_spec(done.spec_path)
    robot = resolve(spec, doc.text.encode(), done.spec_path.name)
    q = np.random.default_rng(3).uniform(-1, 1, len(robot.movable_joints))
    fast = axis_inertias(robot, q)
    for joint in robot.movable_joints:
        if joint.type == "prismatic":
            moved = {j.child for j in robot.joints} & _below(robot, joint.child)
            want = sum(lk.inertial.mass for lk in robot.links if lk.name in moved and lk.inertial)
        else:
            want = axis_inertia(robot, joint.name, q)
        assert fast[joint.name] == pytest.approx(want, rel=1e-9, abs=1e-12), joint.name
    assert len(fast) == len(parents)


def _below(robot, link: str) -> set[str]:
    out, stack = set(), [link]
    while stack:
        node = stack.pop()
        out.add(node)
        stack.extend(j.child for j in robot.joints if j.parent == node)
    return out
