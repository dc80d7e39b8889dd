"""Shared fixtures: each robot's kit is built once per test session and shared read-only.

Tests must not modify a shared kit; copy it (`shutil.copytree`) first if they need to.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from simkit.build import BuildResult, build

REPO = Path(__file__).resolve().parents[1]
SPECS = Path(__file__).resolve().parent / "specs"


@pytest.fixture(scope="session")
def kit_factory(tmp_path_factory):
    """`kit_factory(name_or_yaml)` -> BuildResult, built (and checked) once per session."""
    cache: dict[str, BuildResult] = {}
    out = tmp_path_factory.mktemp("kits")

    def get(target: str) -> BuildResult:
        if target not in cache:
            cache[target] = build(target, out)
        return cache[target]

    return get


@pytest.fixture(scope="session")
def rosie_1000(kit_factory) -> BuildResult:
    return kit_factory("rosie_1000")
