"""Corpus robots for the tests, picked by what their URDF has, never by name: the smallest
example-robot-data URDF (file size, then path) that a test's rule accepts."""

from __future__ import annotations

import site
import sys
import xml.etree.ElementTree as ET
from collections.abc import Callable
from pathlib import Path

import pytest


def corpus() -> Path | None:
    """example-robot-data's robots folder (the test extra installs it), or None."""
    for base in [*site.getsitepackages(), *sys.path]:
        path = Path(base) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
        if path.is_dir():
            return path
    return None


def pick(keep: Callable[[ET.Element], bool]) -> Path:
    """The smallest corpus URDF whose `<robot>` element `keep` accepts. The test is skipped
    where the corpus is not installed, and fails where no URDF in it qualifies."""
    root = corpus()
    if root is None:
        pytest.skip("example-robot-data is not installed (test extra)")
    for path in sorted(root.rglob("*.urdf"), key=lambda p: (p.stat().st_size, p.as_posix())):
        try:
            robot = ET.parse(path).getroot()
        except ET.ParseError:
            continue
        if keep(robot):
            return path
    pytest.fail("no example-robot-data URDF has what this test needs")


def movable(robot: ET.Element) -> list[str]:
    """The types of the URDF's joints other than fixed ones."""
    return [j.get("type", "") for j in robot.iter("joint") if j.get("type") != "fixed"]


def meshes(robot: ET.Element, kind: str) -> list[str]:
    """The filenames of the URDF's `kind` ("visual" or "collision") meshes."""
    return [m.get("filename", "") for e in robot.iter(kind) for m in e.iter("mesh")]
