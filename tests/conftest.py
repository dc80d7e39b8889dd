"""Shared fixtures: each robot's kit is built once per test session and shared read-only.

Tests must not modify a shared kit; copy it (`shutil.copytree`) first if they need to.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from simkit.pipeline import BuildResult, build

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


@pytest.fixture(scope="session")
def rosie_1000_published(tmp_path_factory) -> tuple[Path, dict]:
    """(site folder, index) of `simkit publish rosie_1000`: a second, independent build of
    rosie_1000, without the cache, which the reproducibility test compares with `rosie_1000`
    (so a cache hit and a fresh computation must give the same bytes)."""
    from simkit.kitio.cache import Cache
    from simkit.publish import publish

    out = tmp_path_factory.mktemp("published") / "sim"
    return out, publish(out, ["rosie_1000"], cache=Cache.disabled())


@pytest.fixture(scope="session")
def spec_variant(tmp_path_factory):
    """`spec_variant(spec, old, new)` -> BuildResult of a copy of the spec file `spec` with the
    text `old` replaced by `new` once (same file name, own folder and --out), built once per
    session: a kit that differs from its seed by one edit, for `simkit diff`."""
    cache: dict[tuple, BuildResult] = {}

    def get(spec: Path, old: str, new: str) -> BuildResult:
        key = (str(spec), old, new)
        if key not in cache:
            text = spec.read_text()
            assert old in text, (spec, old)
            folder = tmp_path_factory.mktemp("variant")
            (folder / spec.name).write_text(text.replace(old, new, 1))
            cache[key] = build(str(folder / spec.name), folder / "out")
        return cache[key]

    return get


#: XLA flags for the tests that compile an MJX rollout on the CPU and run it for a few steps:
#: compiling is their time, and these cut it to about half with the same numbers (see
#: scripts/bench_gpu.py's PROBE_XLA_FLAGS, which its --probe sets itself).
XLA_COMPILE_FLAGS = "--xla_backend_optimization_level=0 --xla_cpu_use_fusion_emitters=false"

#: The five seed robots (robots/*.yaml).
SEED_ROBOTS = ("asimov", "ecn_2r", "rosie_1000", "rosie_1400", "rosie_600")


@pytest.fixture(scope="session")
def seed_kits(kit_factory) -> dict[str, BuildResult]:
    """Every seed robot's kit, built once per session (shared with `kit_factory`)."""
    return {name: kit_factory(name) for name in SEED_ROBOTS}


@pytest.fixture(scope="session")
def ecn_2r_mjx_demo(kit_factory) -> subprocess.CompletedProcess:
    """One run of ecn_2r's examples/mjx_demo.py (3 worlds, 5 steps), from inside its kit,
    with XLA_COMPILE_FLAGS: the tests of the demo's output share it, as each run compiles its
    rollout anew (25 to 30 s on a 2-core CPU with XLA's defaults). Tests using it carry
    `xdist_group("mjx_demo")`, so one pytest-xdist worker runs it once."""
    flags = f"{XLA_COMPILE_FLAGS} {os.environ.get('XLA_FLAGS', '')}"
    return subprocess.run(
        [sys.executable, "examples/mjx_demo.py", "--batch", "3", "--steps", "5"],
        cwd=kit_factory("ecn_2r").kit_dir,
        env={**os.environ, "XLA_FLAGS": flags},
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )


def pytest_addoption(parser):
    parser.addoption(
        "--update-golden",
        action="store_true",
        help="rewrite tests/golden/ from the current emitters instead of comparing",
    )


#: Fixtures that build (and check) real kits: a test using any of them is in the slow tier.
KIT_FIXTURES = {
    "ecn_2r_mjx_demo",
    "kit_factory",
    "rosie_1000",
    "rosie_1000_published",
    "seed_kits",
    "spec_variant",
}


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist reads the groups (--dist loadgroup)
def pytest_collection_modifyitems(config, items):
    """Mark kit-building tests `slow`, so `pytest -m "not slow"` is the fast unit tier. Tests
    that build without these fixtures carry an explicit `@pytest.mark.slow`.

    Under pytest-xdist (`-n`, pyproject's addopts) each test file is one group, run whole by
    one worker, so a module-scoped fixture (a probe subprocess, a kit import) is computed
    once and not once per worker; a test that names its own `xdist_group` (Ray's, the MJX
    demo's) joins that group instead."""
    for item in items:
        if KIT_FIXTURES & set(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.slow)
        if item.get_closest_marker("xdist_group") is None:
            item.add_marker(pytest.mark.xdist_group(item.path.name))
