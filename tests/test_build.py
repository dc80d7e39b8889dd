"""Pipeline behaviour: atomic publish, the check command, and the CLI's listing."""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from simkit.check import run_checks
from simkit.errors import CheckFailed
from simkit.pipeline import build

REPO = Path(__file__).resolve().parents[1]


def _digest_tree(root: Path) -> dict[str, str]:
    return {
        p.relative_to(root).as_posix(): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def test_failed_build_keeps_previous_kit(rosie_1000, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    shutil.copytree(rosie_1000.kit_dir, out / rosie_1000.kit_dir.name)
    shutil.copy(rosie_1000.zip_path, out / rosie_1000.zip_path.name)
    before = _digest_tree(out)
    # a spec that validates but whose published mass disagrees with its links: the check fails
    spec = tmp_path / "rosie_1000.yaml"
    spec.write_text(
        (REPO / "robots/rosie_1000.yaml")
        .read_text()
        .replace("mass: 38.6                  # kg", "mass: 40.0                  # kg")
    )
    with pytest.raises(CheckFailed, match=r"published\.mass"):
        build(str(spec), out)
    assert _digest_tree(out) == before
    assert sorted(p.name for p in out.iterdir()) == [
        rosie_1000.zip_path.name,
        rosie_1000.kit_dir.name,
    ]


def test_check_passes_on_built_kit_and_fails_on_tampered_copy(rosie_1000, tmp_path):
    assert all(f.ok for f in run_checks(rosie_1000.kit_dir))
    copy = tmp_path / "kit"
    shutil.copytree(rosie_1000.kit_dir, copy)
    mjcf = copy / "mjcf/rosie_1000.xml"
    mjcf.write_text(mjcf.read_text().replace('mass="10.4"', 'mass="11.4"', 1))
    failed = {f.check for f in run_checks(copy) if not f.ok}
    assert "mass.mjcf" in failed
    proc = subprocess.run(
        [sys.executable, "-m", "simkit.cli", "check", str(copy)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 3
    assert "FAIL mass.mjcf" in proc.stdout and "expected" in proc.stdout


# (file, text in the kit, tampered text, the check that must fail): one per number the kit
# page fixes in the URDF and MJCF ("Simulation parameters") and the tool frame's orientation.
TAMPER = [
    ("urdf", 'effort="150"', 'effort="15"', "urdf.effort"),
    ("urdf", 'velocity="3.141592654"', 'velocity="31.41592654"', "urdf.velocity"),
    ("urdf", 'lower="-2.35619449"', 'lower="-1.35619449"', "urdf.limits"),
    ("urdf", 'damping="0.8"', 'damping="8"', "urdf.dynamics"),
    ("urdf", 'rpy="3.141592654 0 0"', 'rpy="0 0 0"', "fk.yourdfpy_vs_robot_json.rotation"),
    ("mjcf", 'quat="0 1 0 0"', 'quat="1 0 0 0"', "fk.mjcf_vs_robot_json.rotation"),
    # base_link's CoM and tensor orientation: no joint moves it, so no torque shows them
    ("urdf", 'xyz="-0.00333113457 0 -0.04950452243"', 'xyz="0 0 -0.04950452243"', "com.urdf"),
    ("urdf", 'ixz="-0.001401866609"', 'ixz="0.001401866609"', "inertia.urdf"),
    ("mjcf", 'pos="-0.00333113457 0 -0.04950452243"', 'pos="0 0 -0.0495045224"', "com.mjcf"),
    (
        "mjcf",
        "0.02511500894 0 -0.001401866609 0",
        "0.02511500894 0 0.001401866609 0",
        "inertia.mjcf",
    ),
    ("mjcf", 'kp="15000"', 'kp="150000"', "mjcf.servo_gains"),
    ("mjcf", 'kv="340.0092371"', 'kv="34.00092371"', "mjcf.servo_gains"),
    ("mjcf", 'forcerange="-191.9 191.9"', 'forcerange="-150 150"', "mjcf.forcerange"),
    ("mjcf", 'ctrlrange="-2.792526803', 'ctrlrange="-1.792526803', "mjcf.ctrlrange"),
    ("mjcf", 'armature="0.357035"', 'armature="0.0357035"', "mjcf.joint_dynamics"),
    ("mjcf", 'range="-2.792526803', 'range="-1.792526803', "mjcf.range"),
    ("mjcf", '<exclude body1="link_3" body2="link_4" />', "", "mjcf.excludes"),
    (
        "mjcf",
        '<exclude body1="link_3" body2="link_4" />',
        '<exclude body1="link_3" body2="link_4" /><exclude body1="link_1" body2="link_5" />',
        "mjcf.excludes",
    ),
]


@pytest.mark.parametrize(("kind", "old", "new", "check"), TAMPER, ids=[t[3] for t in TAMPER])
def test_checks_catch_a_tampered_urdf_or_mjcf(rosie_1000, tmp_path, kind, old, new, check):
    from simkit.check.mujoco import check_models, check_parameters
    from simkit.check.urdf import check_urdf

    checks = {"models": check_models, "mjcf_parameters": check_parameters, "urdf": check_urdf}
    assert all(f.ok for f in run_checks(rosie_1000.kit_dir, checks))
    copy = tmp_path / "kit"
    shutil.copytree(rosie_1000.kit_dir, copy)
    path = copy / ("urdf/rosie_1000.urdf" if kind == "urdf" else "mjcf/rosie_1000.xml")
    text = path.read_text()
    assert old in text, old
    # ctrlrange and range: a trailing space or quote tells the two apart
    if old.startswith('range="'):
        text = text.replace(" " + old, " " + new, 1)
    else:
        text = text.replace(old, new, 1)
    path.write_text(text)
    failed = {f.check for f in run_checks(copy, checks) if not f.ok}
    assert check in failed


def test_check_of_a_kit_missing_a_file_fails_without_a_traceback(rosie_1000, tmp_path):
    """A damaged kit (here: no MJCF) gives failed findings naming the file, not a crash."""
    copy = tmp_path / "kit"
    shutil.copytree(rosie_1000.kit_dir, copy)
    (copy / "mjcf/rosie_1000.xml").unlink()
    failed = {f.check: f for f in run_checks(copy) if not f.ok}
    assert "mjcf.compile" in failed and "hold.error" in failed
    assert "rosie_1000.xml" in failed["hold.error"].detail
    assert all("\n" not in f.line() for f in failed.values())


def test_check_writes_nothing_into_the_kit(rosie_1000, tmp_path):
    """`simkit check` reads a kit as it is (it may be read-only or checked twice at once):
    no check writes into it (compiling the URDF in MuJoCo uses a copy elsewhere)."""
    from simkit.check.kit import Kit
    from simkit.check.mujoco import load_urdf_in_mujoco

    copy = tmp_path / "kit"
    shutil.copytree(rosie_1000.kit_dir, copy)
    folders = [copy, *(p for p in copy.rglob("*") if p.is_dir())]
    before = {p: p.stat().st_mtime_ns for p in folders}
    assert load_urdf_in_mujoco(Kit.open(copy)).nmesh > 0
    assert all(f.ok for f in run_checks(copy))
    assert {p: p.stat().st_mtime_ns for p in folders} == before


def test_kit_layout_and_zip(rosie_1000):
    kit = rosie_1000.kit_dir
    assert kit.name == "rosie_1000_description"
    assert rosie_1000.zip_path.name == "rosie-1000-sim-kit.zip"
    for rel in (
        "README.md",
        "LICENSE.txt",
        "robot.json",
        "urdf/rosie_1000.urdf",
        "mjcf/rosie_1000.xml",
        "meshes/visual/link_3.stl",
    ):
        assert (kit / rel).is_file(), rel
    import zipfile

    with zipfile.ZipFile(rosie_1000.zip_path) as archive:
        names = archive.namelist()
        assert names == sorted(names)
        assert all(n.startswith("rosie_1000_description/") for n in names)
        assert all(i.date_time == (1980, 1, 1, 0, 0, 0) for i in archive.infolist())
        assert (
            archive.read("rosie_1000_description/robot.json") == (kit / "robot.json").read_bytes()
        )
    doc = json.loads((kit / "robot.json").read_text())
    assert "/" not in doc["provenance"]["spec"].split("robots/")[0]  # no absolute paths


def test_no_absolute_paths_in_any_kit_file(rosie_1000):
    """No file of the kit (or the zip, which holds the same bytes) names the build folder,
    the repository or the home folder: kits are relocatable and reproducible."""
    needles = {str(p).encode() for p in (rosie_1000.kit_dir.parent, REPO, Path.home())}
    for path, data in rosie_1000.files.items():
        if path.endswith((".stl", ".glb", ".usdc")):  # binary geometry: no text to carry a path
            continue
        hits = [n for n in needles if n in data]
        assert not hits, (path, hits)


def test_cli_list_and_version():
    proc = subprocess.run(
        [sys.executable, "-m", "simkit.cli", "list"], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 0
    names = proc.stdout.split()
    assert {"rosie_600", "rosie_1000", "rosie_1400"} <= set(names)
    assert names == sorted(names)


@pytest.mark.slow
def test_check_on_missing_folder_is_one_line(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "simkit.cli", "check", str(tmp_path / "nope")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode != 0
    assert len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr


@pytest.mark.slow
def test_warm_rebuild_reuses_check_findings_of_identical_kit(tmp_path):
    from simkit.kitio.cache import Cache

    spec = REPO / "tests/specs/planar_2r.yaml"
    cold = Cache.at(tmp_path / "cache")
    first = build(str(spec), tmp_path / "a", cache=cold)
    assert cold.stats.misses.get("checks") == 1 and not cold.stats.hits.get("checks")
    warm = Cache.at(tmp_path / "cache")
    second = build(str(spec), tmp_path / "b", cache=warm)
    assert warm.stats.hits.get("checks") == 1 and warm.stats.hits.get("emit") == 1
    assert second.findings == first.findings and all(f.ok for f in second.findings)
    assert second.files == first.files
    # a different kit (one changed byte in the spec's title) is checked afresh
    changed = tmp_path / "planar_2r.yaml"
    changed.write_text(spec.read_text().replace("title: Planar 2R", "title: Planar 2R arm"))
    third = Cache.at(tmp_path / "cache")
    build(str(changed), tmp_path / "c", cache=third)
    assert third.stats.misses.get("checks") == 1
