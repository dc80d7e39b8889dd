"""Regenerated kits in a git repository (issue 23): a rebuild of an unchanged spec leaves
`git status` clean (the no-op and the full build alike), a one-value change touches only the
files it reaches, and the kit folder is a plain folder that cp -r, rsync -a and zip -r copy
whole."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SRC = str(REPO / "src")
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(shutil.which("git") is None, reason="needs git"),
]
KIT = "rosie_1000_description"


def _run(cwd: Path, *cmd: str) -> str:
    env = {**os.environ, "PYTHONPATH": SRC}
    proc = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=600, env=env)
    assert proc.returncode == 0, (cmd, proc.stderr)
    return proc.stdout


def _build(repo: Path, *extra: str) -> str:
    return _run(
        repo,
        sys.executable,
        "-m",
        "simkit.cli",
        "build",
        "rosie_1000.yaml",
        "--out",
        "assets",
        "-q",
        *extra,
    )


def _mtimes(root: Path) -> dict[str, int]:
    return {p.relative_to(root).as_posix(): p.stat().st_mtime_ns for p in root.rglob("*")}


def test_regenerating_in_git_is_clean_and_a_change_touches_only_its_files(tmp_path):
    repo = tmp_path / "project"
    repo.mkdir()
    spec = repo / "rosie_1000.yaml"
    spec.write_text((REPO / "robots/rosie_1000.yaml").read_text())
    _run(repo, "git", "init", "-q")
    _run(repo, "git", "config", "user.email", "ci@example.com")
    _run(repo, "git", "config", "user.name", "ci")
    _build(repo)
    assets = repo / "assets"
    assert sorted(p.name for p in assets.iterdir()) == [
        ".rosie_1000.manifest.json",
        "rosie-1000-sim-kit.zip",
        KIT,
    ]
    assert not (assets / KIT).is_symlink() and (assets / KIT).is_dir()
    _run(repo, "git", "add", "-A")
    _run(repo, "git", "commit", "-qm", "kits")
    before = _mtimes(assets)

    assert "nothing changed" in _build(repo)  # the no-op
    assert _run(repo, "git", "status", "--porcelain") == ""
    # a full build from an empty cache (a CI job): the same bytes, nothing rewritten
    assert "nothing rewritten" in _build(repo, "--no-cache")
    assert _run(repo, "git", "status", "--porcelain") == ""
    assert _mtimes(assets) == before

    # a one-value change: the tool (flange) link's mass, with the published total the
    # checks compare against
    text = spec.read_text()
    for old, new in (("    mass: 0.8\n", "    mass: 0.85\n"), ("  mass: 38.6 ", "  mass: 38.65")):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    spec.write_text(text)
    _build(repo)
    changed = set(_run(repo, "git", "diff", "--name-only").split())
    kit = "assets/" + KIT
    must = {
        f"{kit}/robot.json",
        f"{kit}/urdf/rosie_1000.urdf",
        f"{kit}/mjcf/rosie_1000.xml",
        f"{kit}/usd/rosie_1000.usda",
        "assets/rosie-1000-sim-kit.zip",
    }
    assert must <= changed, must - changed
    geometry = (".stl", ".obj", ".glb", ".step", ".dae")
    assert not [p for p in changed if "/meshes/" in p or p.endswith(geometry)]
    assert _run(repo, "git", "status", "--porcelain", "--untracked-files=all").count("??") == 0
    # files git does not list kept their mtime (rsync and make see only the real changes)
    after = _mtimes(assets)
    kept = [p for p in before if f"assets/{p}" not in changed and (assets / p).is_file()]
    assert len(kept) > 20 and all(after[p] == before[p] for p in kept)


def test_cp_rsync_and_zip_of_the_kit_folder_copy_every_file(kit_factory, tmp_path):
    result = kit_factory("rosie_1000")
    kit = result.kit_dir
    assert kit.is_dir() and not kit.is_symlink()
    files = sorted(p.relative_to(kit).as_posix() for p in kit.rglob("*") if p.is_file())
    assert len(files) == len(result.files)

    def listing(root: Path) -> list[str]:
        return sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file())

    subprocess.run(["cp", "-r", str(kit), str(tmp_path / "cp")], check=True)
    assert listing(tmp_path / "cp") == files
    if shutil.which("rsync"):
        subprocess.run(["rsync", "-a", f"{kit}/", str(tmp_path / "rsync")], check=True)
        assert listing(tmp_path / "rsync") == files
    if shutil.which("zip") and shutil.which("unzip"):
        subprocess.run(
            ["zip", "-qr", str(tmp_path / "k.zip"), kit.name], cwd=kit.parent, check=True
        )
        subprocess.run(
            ["unzip", "-q", str(tmp_path / "k.zip"), "-d", str(tmp_path / "unz")], check=True
        )
        assert listing(tmp_path / "unz" / kit.name) == files
