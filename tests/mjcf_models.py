"""Small handwritten MJCF models for the MJCF import tests (issue 31), and a helper that
imports one and returns its spec."""

from __future__ import annotations

from pathlib import Path

import yaml

from simkit.importer import import_robot

#: one link's inertial and collision box, reused by the models below
INERTIAL = '<inertial pos="0 0 0.1" mass="1" diaginertia="0.01 0.01 0.002"/>'
BOX = '<geom type="box" size="0.03 0.03 0.1" pos="0 0 0.1"/>'


def arm(joint: str = '<joint name="j1" axis="0 1 0" range="-1 1"/>', extra: str = "") -> str:
    """A fixed base and one jointed link (`joint` inside the link's body)."""
    return f"""<mujoco model="arm">
  <compiler angle="radian"/>
  <worldbody>
    <body name="base">{INERTIAL}{BOX}
      <body name="link1" pos="0 0 0.2">{joint}{INERTIAL}{BOX}</body>
    </body>
  </worldbody>
  {extra}
</mujoco>
"""


def write(folder: Path, text: str, name: str = "model.xml") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(text)
    return path


def spec_of(path: Path, out: Path, **options) -> dict:
    """Import `path` into `out`; the written spec."""
    done = import_robot(path, out, **options)
    return yaml.safe_load(done.spec_path.read_text())


def joints(spec: dict) -> dict[str, dict]:
    return {j["name"]: j for j in spec["joints"]}


def listed(spec: dict) -> dict[str, str]:
    return {d["what"]: d["reason"] for d in spec.get("source_differences", [])}
