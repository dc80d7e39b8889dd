"""sdf/NAME.sdf: libsdformat (Gazebo's parser) loads every kit's SDF with warnings treated as
errors, and the SDF-vs-URDF check (check/sdf.py) passes on the kits and fails on a tampered SDF.

The loader (tests/sdf_loader.cc) is compiled with g++ against Debian's libsdformat-dev; the
tests skip without them unless SIMKIT_REQUIRE_SDFORMAT is set (.ci/run sets it).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import corpus_pick
from simkit.check.kit import Kit
from simkit.check.sdf import check_sdf
from simkit.emit import sdf
from simkit.pipeline import model_from_spec

HERE = Path(__file__).resolve().parent
LOADER = HERE / "sdf_loader.cc"


def _sdformat_flags() -> list[str] | None:
    """pkg-config flags of the newest libsdformat installed, or None."""
    if shutil.which("pkg-config") is None:
        return None
    listed = subprocess.run(["pkg-config", "--list-all"], capture_output=True, text=True).stdout
    names = sorted(re.findall(r"^(sdformat(\d+))\s", listed, re.M), key=lambda m: int(m[1]))
    if not names:
        return None
    flags = subprocess.run(
        ["pkg-config", "--cflags", "--libs", names[-1][0]], capture_output=True, text=True
    )
    return flags.stdout.split() if flags.returncode == 0 else None


@pytest.fixture(scope="session")
def sdf_loader(tmp_path_factory) -> Path:
    """The compiled loader: `loader FILE...` prints `model NAME links N joints M frames F mass
    KG` per file and exits 1 on any error."""
    flags = _sdformat_flags()
    if shutil.which("g++") is None or flags is None:
        why = "g++ or libsdformat-dev (pkg-config sdformatNN) is missing"
        if os.environ.get("SIMKIT_REQUIRE_SDFORMAT"):
            pytest.fail(f"SIMKIT_REQUIRE_SDFORMAT is set but {why}")
        pytest.skip(why)
    exe = tmp_path_factory.mktemp("sdf_loader") / "sdf_loader"
    subprocess.run(["g++", "-std=c++17", str(LOADER), "-o", str(exe), *flags], check=True)
    return exe


def _load(loader: Path, *files: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(loader), *map(str, files)], capture_output=True, text=True)


def _expect_loaded(loader: Path, kit_dir: Path) -> None:
    """libsdformat loads the kit's SDF: as many links and joints as the file has, and the
    total mass robot.json gives."""
    doc = json.loads((kit_dir / "robot.json").read_text())
    path = kit_dir / "sdf" / f"{doc['name']}.sdf"
    done = _load(loader, path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Warning" not in done.stderr and "Error" not in done.stderr, done.stderr
    text = path.read_text()
    line = done.stdout.split()
    assert line[:2] == ["model", doc["name"]]
    assert int(line[3]) == text.count("<link ") > 0
    assert int(line[5]) == text.count("<joint ")
    assert float(line[9]) == pytest.approx(sum(link["mass"] for link in doc["links"]), rel=1e-6)


def test_libsdformat_loads_every_seed_kit(sdf_loader, seed_kits):
    for result in seed_kits.values():
        _expect_loaded(sdf_loader, result.kit_dir)


def test_libsdformat_refuses_a_broken_model(sdf_loader, tmp_path):
    """The loader is not a rubber stamp: a joint naming a link the model lacks is an error."""
    robot = model_from_spec(str(HERE / "specs" / "planar_2r.yaml"))
    ((_file, data),) = sdf.emit(robot).items()
    good, bad = tmp_path / "good.sdf", tmp_path / "bad.sdf"
    good.write_bytes(data)
    bad.write_text(data.decode().replace("<child>link_2</child>", "<child>link_9</child>"))
    assert _load(sdf_loader, good).returncode == 0
    done = _load(sdf_loader, bad)
    assert done.returncode == 1 and "link_9" in done.stdout, done.stdout


def _continuous(robot) -> bool:
    """Movable joints, all continuous."""
    types = corpus_pick.movable(robot)
    return bool(types) and set(types) == {"continuous"}


def _collada(robot) -> bool:
    """Revolute joints and mesh visuals, COLLADA files only."""
    uris = corpus_pick.meshes(robot, "visual")
    dae = bool(uris) and all(u.lower().endswith(".dae") for u in uris)
    return dae and "revolute" in corpus_pick.movable(robot)


#: Two small example-robot-data robots (the smallest URDFs with these properties,
#: corpus_pick.py): an arm on continuous joints, and one with mesh visuals.
IMPORTED = {"continuous": _continuous, "collada": _collada}


@pytest.mark.slow
@pytest.mark.parametrize("kind", IMPORTED)
def test_libsdformat_loads_imported_robots(sdf_loader, kind, tmp_path):
    source = corpus_pick.pick(IMPORTED[kind])
    name = "imported"
    simkit = [sys.executable, "-m", "simkit.cli"]
    imported = subprocess.run(
        [*simkit, "import", str(source), "--name", name, "--out", str(tmp_path), "-q"],
        capture_output=True,
        text=True,
    )
    assert imported.returncode == 0, imported.stderr
    built = subprocess.run(
        [
            *simkit,
            "build",
            str(tmp_path / f"{name}.yaml"),
            "--out",
            str(tmp_path / "kits"),
            "-q",
            "--no-step",
        ],
        capture_output=True,
        text=True,
    )
    assert built.returncode == 0, built.stdout + built.stderr  # the SDF check passed too
    _expect_loaded(sdf_loader, tmp_path / "kits" / f"{name}_description")


def _failed(kit_dir: Path) -> set[str]:
    return {f.check for f in check_sdf(Kit.open(kit_dir)) if not f.ok}


@pytest.mark.parametrize(
    ("old", "new", "caught"),
    [
        ("<mass>7.084761</mass>", "<mass>7.1</mass>", "sdf.mass"),
        ("<ixz>-0.033179</ixz>", "<ixz>0.033179</ixz>", "sdf.inertia"),
        (
            '<pose relative_to="base_link">0 0 0 0 0 -1.570796327</pose>',
            '<pose relative_to="base_link">0 0 0.001 0 0 -1.570796327</pose>',
            "sdf.joint_poses",
        ),
        ("<xyz>0 0 1</xyz>", "<xyz>0 1 0</xyz>", "sdf.fk"),
        ("<upper>0.0698132</upper>", "<upper>0.07</upper>", "sdf.limits"),
        ("<upper>0.0698132</upper>", "", "sdf.limits"),
        ("<parent>base_link</parent>", "<parent>world</parent>", "sdf.joints"),
        ("../meshes/collision/link_1_00.obj", "../meshes/collision/link_1_99.obj", "sdf.meshes"),
    ],
)
def test_sdf_check_fails_a_tampered_sdf(kit_factory, tmp_path, old, new, caught):
    source = kit_factory("ecn_2r").kit_dir
    assert _failed(source) == set()
    kit = tmp_path / "kit"
    shutil.copytree(source, kit)
    path = kit / "sdf" / "ecn_2r.sdf"
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new, 1))
    assert caught in _failed(kit)


def test_sdf_check_counts_a_missing_inertial_as_gazebos_default(kit_factory, tmp_path):
    """SDFormat gives a link without <inertial> 1 kg: the check sees that, not a match."""
    kit = tmp_path / "kit"
    shutil.copytree(kit_factory("ecn_2r").kit_dir, kit)
    path = kit / "sdf" / "ecn_2r.sdf"
    text = path.read_text()
    start = text.index("<inertial>", text.index('<link name="link_2">'))
    end = text.index("</inertial>", start) + len("</inertial>")
    path.write_text(text[:start] + text[end:])
    assert {"sdf.mass", "sdf.com", "sdf.inertia"} <= _failed(kit)


def test_sdf_of_a_floating_base_has_a_free_canonical_link():
    """Asimov: no joint to the world; the pelvis first, at its floating joint's origin."""
    robot = model_from_spec("asimov")
    text = sdf.emit(robot)["sdf/asimov.sdf"].decode()
    assert "<parent>world</parent>" not in text
    first = re.search(r'<link name="([^"]+)">\s*<pose relative_to="__model__">([^<]+)<', text)
    assert first is not None and first.group(1) == robot.floating_joint.child
    assert [float(v) for v in first.group(2).split()[:3]] == list(robot.floating_joint.xyz)


@pytest.mark.slow
def test_a_joint_named_like_a_link_gets_a_unique_sdf_name(sdf_loader, tmp_path):
    """URDF allows a joint and a link of one name, SDFormat does not: the SDF renames the
    joint, libsdformat loads it and the SDF check pairs the joints by child link."""
    from simkit.pipeline import build

    spec = tmp_path / "clash.yaml"
    spec.write_text((HERE / "specs" / "planar_2r.yaml").read_text().replace("joint_1", "link_1"))
    result = build(str(spec), tmp_path / "out", step=False)  # raises if a check fails
    text = (result.kit_dir / "sdf" / "planar_2r.sdf").read_text()
    assert '<joint name="link_1_joint" type="revolute">' in text
    assert {f.check for f in result.findings if f.check.startswith("sdf.")} >= {"sdf.fk"}
    _expect_loaded(sdf_loader, result.kit_dir)
