"""scripts/usd_corpus.py's comparison reads an original's joint limit of 1e15 or more (SDFormat's
default +-1e16, carried by URDFs made from SDF: a multirotor's rotors) as none: no motion
reaches it, so the joint moves as a continuous one. A limit of a few turns stays a limit, even
where simkit's own import reads it as none (beyond 2 turns): the comparison then says so."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import yaml

from simkit.importer import import_robot

REPO = Path(__file__).resolve().parents[1]

ROTOR = """<?xml version="1.0"?>
<robot name="rotor">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial>
    <collision><geometry><box size="0.2 0.2 0.05"/></geometry></collision>
  </link>
  <joint name="spin" type="revolute">
    <parent link="base"/><child link="prop"/><origin xyz="0 0 0.05"/><axis xyz="0 0 1"/>
    <limit lower="-LIMIT" upper="LIMIT" effort="1" velocity="100"/>
  </joint>
  <link name="prop">
    <inertial><mass value="0.05"/>
      <inertia ixx="0.0001" ixy="0" ixz="0" iyy="0.0002" iyz="0" izz="0.0003"/></inertial>
    <collision><geometry><box size="0.2 0.02 0.005"/></geometry></collision>
  </link>
</robot>
"""


def _compare(tmp_path: Path, limit: str) -> list[str]:
    spec_file = importlib.util.spec_from_file_location("usd_corpus", REPO / "scripts/usd_corpus.py")
    corpus = importlib.util.module_from_spec(spec_file)
    spec_file.loader.exec_module(corpus)
    source = tmp_path / "rotor.urdf"
    source.write_text(ROTOR.replace("LIMIT", limit))
    done = import_robot(source, tmp_path / "out")  # simkit's URDF import: continuous for both
    spec = yaml.safe_load(done.spec_path.read_text())
    assert {j["name"]: j["type"] for j in spec["joints"]}["spin"] == "continuous"
    return corpus.compare_urdf(source, spec)


def test_placeholder_limit_is_none(tmp_path) -> None:
    assert _compare(tmp_path, "1e+16") == []


def test_few_turns_stay_a_limit(tmp_path) -> None:
    problems = _compare(tmp_path, "20")
    assert any("revolute in the original, continuous in the kit" in p for p in problems)
