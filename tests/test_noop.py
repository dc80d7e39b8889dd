"""The no-op rebuild (kitio/noop.py): `simkit build` of an unchanged spec writes nothing,
imports nothing heavy and says so in one line; any change to what decides the output (spec
bytes, a mesh the spec names, simkit's code or templates, an installed library, an option)
or to the published files runs the full build, which writes only what differs."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from simkit.kitio import layout, manifest, noop
from tree_snapshot import snapshot

REPO = Path(__file__).resolve().parents[1]
SRC = str(REPO / "src")
pytestmark = pytest.mark.slow  # builds a real kit


def _cli(*args: str, env: dict | None = None) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": SRC, **(env or {})}
    cmd = [sys.executable, "-m", "simkit.cli", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)


_snapshot = snapshot


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """A planar 2R arm whose base is a mesh file (its hull as collision: no CoACD), built once
    with the CLI into `out` with its own cache folder: (spec, mesh, out, cache)."""
    root = tmp_path_factory.mktemp("noop")
    mesh = root / "part.stl"
    shutil.copy(REPO / "tests/specs/meshes/bracket.stl", mesh)
    text = (REPO / "tests/specs/planar_2r.yaml").read_text()
    base = "      - {shape: cylinder, radius: 0.05, from: [0, 0, 0], to: [0, 0, 0.05]}\n"
    assert base in text
    text = text.replace(base, "      - {shape: mesh, file: part.stl}\n", 1)
    given = "    collision: given\n    collision_shapes:\n      - {shape: mesh, file: part.stl}\n"
    text = text.replace("    collision: primitives\n", given, 1)
    spec = root / "planar_2r.yaml"
    spec.write_text(text)
    out, cache = root / "out", root / "cache"
    proc = _cli("build", str(spec), "--out", str(out), "--cache-dir", str(cache), "-q")
    assert proc.returncode == 0, proc.stderr
    return spec, mesh, out, cache


def _unchanged(built, **options) -> str | None:
    spec, _, out, cache = built
    opts = noop.options(**{"usd_format": "usda", "step": True, "check": True, **options})
    return noop.unchanged(str(spec), out, cache, opts)


def test_a_rebuild_with_nothing_changed_writes_nothing_and_imports_nothing_heavy(built):
    spec, _, out, cache = built
    before = _snapshot(out)
    code = (
        "import sys; from simkit.cli import main; "
        f"main(['build', {str(spec)!r}, '--out', {str(out)!r}, '--cache-dir', {str(cache)!r}], "
        "standalone_mode=False); "
        "print(sorted(m for m in ('numpy', 'pydantic', 'mujoco', 'simkit.pipeline') "
        "if m in sys.modules))"
    )
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    line, imported = proc.stdout.strip().splitlines()
    assert line.startswith("planar_2r: nothing changed") and "checks of that build stand" in line
    assert imported == "[]"
    assert _snapshot(out) == before


@pytest.mark.parametrize(
    "options",
    [{"usd_format": "usdc"}, {"step": False}, {"check": False}],
    ids=["usd-format", "no-step", "no-check"],
)
def test_an_option_that_changes_output_or_checking_is_no_noop(built, options):
    assert _unchanged(built) is not None
    assert _unchanged(built, **options) is None


def test_a_changed_spec_or_named_mesh_is_no_noop(built):
    spec, mesh, _, _ = built
    assert _unchanged(built) is not None
    for path, edit in (
        (spec, lambda b: b + b"# a comment\n"),
        (mesh, lambda b: b"changed header".ljust(80, b" ") + b[80:]),  # same size and geometry
    ):
        original = path.read_bytes()
        path.write_bytes(edit(original))
        assert _unchanged(built) is None, path.name
        path.write_bytes(original)  # the same bytes again (new mtime): hashed, and a no-op
        assert _unchanged(built) is not None, path.name


def test_changed_code_templates_or_libraries_change_the_key(built, tmp_path, monkeypatch):
    package = tmp_path / "simkit"
    shutil.copytree(Path(noop.__file__).resolve().parents[1], package)
    templates = tmp_path / "templates"
    shutil.copytree(REPO / "templates", templates)
    first = noop.code_digest(package, templates)
    assert first == noop.code_digest()
    with (package / "pipeline.py").open("a") as handle:
        handle.write("# an edit\n")
    assert noop.code_digest(package, templates) != first
    shutil.copy(REPO / "src/simkit/pipeline.py", package / "pipeline.py")
    readme = next(p for p in sorted(templates.rglob("*")) if p.is_file())
    readme.write_bytes(readme.read_bytes() + b"\n")
    assert noop.code_digest(package, templates) != first
    # a library installed or upgraded: a new dist-info on sys.path
    assert _unchanged(built) is not None
    site = tmp_path / "site"
    (site / "somelib-1.0.dist-info").mkdir(parents=True)
    # a folder on the start-up path (PYTHONPATH, site-packages) as the next process sees it
    monkeypatch.setattr(noop, "_IMPORT_PATH", (str(site), *noop._IMPORT_PATH))
    assert _unchanged(built) is None
    os.rename(site / "somelib-1.0.dist-info", site / "somelib-1.1.dist-info")
    assert _unchanged(built) is None


def test_a_changed_or_added_published_file_is_no_noop(built):
    out = built[2]
    kit = out / layout.kit_dir_name("planar_2r")
    target = kit / "robot.json"
    original = target.read_bytes()
    target.write_bytes(original.replace(b'"planar_2r"', b'"planar_2x"', 1))
    assert len(target.read_bytes()) == len(original)
    assert _unchanged(built) is None
    target.write_bytes(original)
    assert _unchanged(built) is not None
    extra = kit / "notes.txt"
    extra.write_text("x")
    assert _unchanged(built) is None
    extra.unlink()
    journal = out / manifest.journal_name("planar_2r")
    journal.mkdir()
    assert _unchanged(built) is None
    journal.rmdir()
    assert _unchanged(built) is not None


def test_a_full_rebuild_with_the_same_output_rewrites_nothing(built):
    """A change that changes no output byte (the mesh file's STL header, which no reader
    uses) misses the no-op; the full build then finds every file equal and leaves --out as
    it was, to the mtime."""
    spec, mesh, out, cache = built
    before = _snapshot(out)
    original = mesh.read_bytes()
    mesh.write_bytes(b"another header".ljust(80, b" ") + original[80:])
    try:
        proc = _cli("build", str(spec), "--out", str(out), "--cache-dir", str(cache), "-q")
    finally:
        mesh.write_bytes(original)
    assert proc.returncode == 0, proc.stderr
    assert "nothing rewritten" in proc.stdout
    assert _snapshot(out) == before
