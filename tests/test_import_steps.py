"""The importer's shape (issue 22): one in-memory draft through ordered steps, written and
validated once; the base decided from the robot's structure; URDF names kept; masses
estimated from the visual solid where the URDF gives none."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from simkit.importer import import_robot
from simkit.importer import write as writer

URDF = Path(__file__).resolve().parent / "specs" / "urdf"
ARM = URDF / "pkg_demo" / "urdf" / "arm.urdf"


def _inertial(mass: float | None, xyz: str = "0 0 0") -> str:
    if mass is None:
        return ""
    return (
        f'<inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
        '<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>'
    )


def box(name: str, size: str, xyz: str = "0 0 0", mass: float | None = 1.0) -> str:
    """A link: a box (visual and collision) at `xyz`, with `mass` kg there (None: none)."""
    geometry = f'<origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry>'
    return (
        f'<link name="{name}">{_inertial(mass, xyz)}<visual>{geometry}</visual>'
        f"<collision>{geometry}</collision></link>"
    )


def joint(name, kind, parent, child, xyz, axis="0 1 0", lower=-1.0, upper=1.0, effort=50):
    limit = f'<limit lower="{lower}" upper="{upper}" effort="{effort}" velocity="2"/>'
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>{limit if kind != "fixed" else ""}</joint>'
    )


def write(tmp_path: Path, body: str, name: str = "robot") -> Path:
    path = tmp_path / f"{name}.urdf"
    path.write_text(f'<?xml version="1.0"?>\n<robot name="{name}">{body}</robot>\n')
    return path


def test_one_import_writes_and_validates_the_spec_once(tmp_path, monkeypatch):
    calls = {"spec_yaml": 0, "check": 0}
    spec_yaml, check = writer.spec_yaml, writer.check

    def counted_yaml(*args, **kwargs):
        calls["spec_yaml"] += 1
        return spec_yaml(*args, **kwargs)

    def counted_check(*args, **kwargs):
        calls["check"] += 1
        return check(*args, **kwargs)

    monkeypatch.setattr(writer, "spec_yaml", counted_yaml)
    monkeypatch.setattr(writer, "check", counted_check)
    done = import_robot(ARM, tmp_path)
    assert calls == {"spec_yaml": 1, "check": 1}
    assert yaml.safe_load(done.spec_path.read_text())["name"] == "arm"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".import-")] == []


def test_reimport_is_byte_identical_and_leaves_no_stale_mesh(tmp_path):
    first = import_robot(ARM, tmp_path / "out")
    files = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    stale = tmp_path / "out" / "meshes" / "gone.stl"
    spec = yaml.safe_load(first.spec_path.read_text())
    mesh = next(s for link in spec["links"] for s in link.get("solid", []) if "file" in s)
    # an earlier import that used a mesh this one does not
    stale.write_bytes((tmp_path / "out" / mesh["file"]).read_bytes())
    text = first.spec_path.read_text().replace(mesh["file"], "meshes/gone.stl", 1)
    first.spec_path.write_text(text)
    import_robot(ARM, tmp_path / "out")
    again = {p: p.read_bytes() for p in (tmp_path / "out").rglob("*") if p.is_file()}
    assert again == files


def _biped(fold: bool = False) -> str:
    """A pelvis with two legs hanging 0.5 m below it and two arms; `fold`: the hands hang
    inside the thighs at the zero pose (a humanoid's arms through its legs)."""
    arm_y = "0.1" if fold else "0.25"
    body = box("pelvis", "0.3 0.3 0.1", mass=5.0)
    for side, y in (("l", ""), ("r", "-")):
        body += box(f"{side}_thigh", "0.08 0.08 0.5", "0 0 -0.25", 2.0)
        body += joint(f"{side}_hip", "revolute", "pelvis", f"{side}_thigh", f"0 {y}0.1 -0.05")
        body += box(f"{side}_arm", "0.04 0.04 0.4", "0 0 -0.2", 0.5)
        body += joint(f"{side}_shoulder", "revolute", "pelvis", f"{side}_arm",
                      f"0 {y}{arm_y} 0.05", axis="1 0 0", lower=-1.5, upper=1.5)  # fmt: skip
    return body


def _arm() -> str:
    body = box("base", "0.1 0.1 0.1", "0 0 0.05", 2.0)
    body += box("upper", "0.05 0.05 0.3", "0 0 0.15", 1.0)
    body += box("fore", "0.04 0.04 0.3", "0 0 0.15", 0.5)
    body += joint("shoulder", "revolute", "base", "upper", "0 0 0.1")
    body += joint("elbow", "revolute", "upper", "fore", "0 0 0.3")
    return body


def test_legs_make_a_floating_base_and_an_arm_a_fixed_one(tmp_path):
    biped = import_robot(write(tmp_path, _biped(), "biped"), tmp_path / "biped")
    spec = yaml.safe_load(biped.spec_path.read_text())
    assert spec.get("floating_base") and spec["joints"][0]["type"] == "floating"
    assert any("floating base: 4 limbs reach" in line for line in biped.lines)  # arms too
    arm = import_robot(write(tmp_path, _arm(), "arm"), tmp_path / "arm")
    spec = yaml.safe_load(arm.spec_path.read_text())
    assert not spec.get("floating_base") and spec["joints"][0]["type"] == "fixed"
    assert any("fixed base: the root link 'base'" in line for line in arm.lines)
    bolted = import_robot(write(tmp_path, _biped(), "biped"), tmp_path / "bolted", floating=False)
    spec = yaml.safe_load(bolted.spec_path.read_text())
    assert spec["joints"][0]["type"] == "fixed"
    assert not any("floating base:" in line or "fixed base:" in line for line in bolted.lines)


def test_cli_base_flags_override_and_exclude_each_other(tmp_path):
    from click.testing import CliRunner

    from simkit.cli import main

    path = write(tmp_path, _biped(), "biped")
    result = CliRunner().invoke(main, ["import", str(path), "--out", str(tmp_path / "a"),
                                       "--fixed-base", "-q"])  # fmt: skip
    assert result.exit_code == 0, result.output
    assert yaml.safe_load((tmp_path / "a" / "biped.yaml").read_text())["joints"][0]["type"] == (
        "fixed"
    )
    both = CliRunner().invoke(main, ["import", str(path), "--out", str(tmp_path / "b"),
                                     "--fixed-base", "--floating-base"])  # fmt: skip
    assert both.exit_code != 0 and "exclude each other" in both.output


def test_legged_robot_bolted_at_the_pelvis_gets_a_home_free_of_contact(tmp_path):
    """--fixed-base on a humanoid whose hands hang inside its thighs: the home search moves
    the arms out (and keeps the legs as they hang), reported."""
    import mujoco
    import numpy as np

    from simkit.importer.fixups import collide
    from simkit.model.resolve import resolve
    from simkit.spec.validate import load_spec

    path = write(tmp_path, _biped(fold=True), "folded")
    done = import_robot(path, tmp_path / "out", floating=False)
    spec, doc = load_spec(done.spec_path)
    home = dict(spec.poses)["home"]
    names = [j.name for j in spec.joints if j.type == "revolute"]
    moved = {n for n, v in zip(names, home, strict=True) if v != 0.0}
    assert moved and moved <= {"l_shoulder", "r_shoulder"}
    assert any("home: the links collide" in line for line in done.lines)
    robot = resolve(spec, doc.text.encode(), done.spec_path.name)
    xml = collide.model_xml(robot, done.spec_path.parent, (), collide.covered_shapes)
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    adr = [model.jnt_qposadr[model.joint(n).id] for n in names]
    collide.penetration(model, data, np.array(adr), np.array(home))
    assert not collide.touching(data)


def test_fixed_joint_names_are_kept(tmp_path):
    """A massless leaf on a fixed joint becomes a frame that keeps the URDF joint's name,
    `-` and all (the kit's URDF writes it); only a name the kit cannot hold is renamed."""
    body = _arm() + '<link name="tool0"/>'
    body += '<joint name="fore-tool0_fixed_joint" type="fixed"><parent link="fore"/>'
    body += '<child link="tool0"/><origin xyz="0 0 0.3"/></joint>'
    body += '<link name="cam"/><joint name="cam joint" type="fixed"><parent link="fore"/>'
    body += '<child link="cam"/></joint>'
    done = import_robot(write(tmp_path, body, "tool"), tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    frames = {f["name"]: f for f in spec["frames"]}
    assert frames["tool0"]["joint"] == "fore-tool0_fixed_joint"
    assert frames["cam"]["joint"] == "cam_joint"  # a space: renamed, reported
    assert any("'cam_joint'" in line and "renamed" in line for line in done.lines)
    assert not any("fore-tool0" in line for line in done.lines)
    from simkit.emit import urdf
    from simkit.model.resolve import resolve
    from simkit.spec.validate import load_spec

    loaded, doc = load_spec(done.spec_path)
    robot = resolve(loaded, doc.text.encode(), done.spec_path.name)
    text = b"".join(urdf.emit(robot).values()).decode()
    assert '<joint name="fore-tool0_fixed_joint" type="fixed">' in text


def _no_inertials(tmp_path: Path) -> Path:
    """An arm whose URDF has no <inertial> at all: a box base, a box upper arm and a mesh
    forearm (a closed 0.1 x 0.1 x 0.2 m box mesh)."""
    import trimesh

    (tmp_path / "fore.stl").write_bytes(
        trimesh.creation.box((0.1, 0.1, 0.2)).export(file_type="stl")
    )
    fore = (
        '<link name="fore"><visual><origin xyz="0 0 0.1"/><geometry>'
        '<mesh filename="fore.stl"/></geometry></visual></link>'
    )
    body = box("base", "0.2 0.2 0.1", "0 0 0.05", None)
    body += box("upper", "0.05 0.05 0.3", "0 0 0.15", None) + fore
    body += joint("shoulder", "revolute", "base", "upper", "0 0 0.1")
    body += joint("elbow", "revolute", "upper", "fore", "0 0 0.3")
    return write(tmp_path, body, "bare")


def test_urdf_without_inertials_gets_the_mass_of_its_solids(tmp_path):
    path = _no_inertials(tmp_path)
    done = import_robot(path, tmp_path / "out")
    links = {link["name"]: link for link in yaml.safe_load(done.spec_path.read_text())["links"]}
    assert abs(links["base"]["mass"] - 1400 * 0.2 * 0.2 * 0.1) < 1e-6  # 5.6 kg (the median link)
    assert abs(links["upper"]["mass"] - 1400 * 0.05 * 0.05 * 0.3) < 1e-6
    assert abs(links["fore"]["mass"] - 1400 * 0.1 * 0.1 * 0.2) < 1e-3  # the mesh's volume
    assert abs(links["fore"]["com"][2] - 0.1) < 1e-6
    fore = links["fore"]["inertia"]  # a solid box: m (a^2 + b^2) / 12
    assert abs(fore["ixx"] - 2.8 * (0.1**2 + 0.2**2) / 12) < 1e-6
    assert {"mass", "com", "inertia"} <= set(links["upper"]["estimated"])
    lines = [ln for ln in done.lines if "visual solid's volume" in ln]
    assert len(lines) == 3 and all("1400 kg/m^3" in ln for ln in lines)
    light = import_robot(path, tmp_path / "light", density=1000.0)
    links = {link["name"]: link for link in yaml.safe_load(light.spec_path.read_text())["links"]}
    assert abs(links["upper"]["mass"] - 1000 * 0.05 * 0.05 * 0.3) < 1e-6


def test_estimated_armature_never_swamps_what_the_joint_moves(tmp_path):
    """A 10 g finger on a 10 N m joint: 0.001 x effort would be 0.01 kg m^2, thousands of
    times its own inertia; the armature is held to that inertia and the servo softened so it
    keeps its frequency. A heavy link keeps 0.001 x effort."""
    from simkit.importer.fixups.rotors import SERVO_OMEGA

    body = box("base", "0.1 0.1 0.1", "0 0 0.05", 5.0)
    body += box("upper", "0.05 0.05 0.4", "0 0 0.2", 8.0)
    body += box("tip", "0.01 0.01 0.05", "0 0 0.025", 0.01).replace(
        'ixx="0.001" iyy="0.001" izz="0.001"', 'ixx="1e-6" iyy="1e-6" izz="1e-6"'
    )
    body += joint("shoulder", "revolute", "base", "upper", "0 0 0.1", effort=100)
    body += joint("finger", "revolute", "upper", "tip", "0 0 0.4", effort=10)
    done = import_robot(write(tmp_path, body, "finger"), tmp_path / "out")
    joints = {j["name"]: j for j in yaml.safe_load(done.spec_path.read_text())["joints"]}
    assert joints["shoulder"]["armature"] == 0.1 and "kp" not in joints["shoulder"]
    finger = joints["finger"]
    own = 1e-6 + 0.01 * 0.025**2  # its inertia about its CoM plus m d^2: 7.25e-6 kg m^2
    assert finger["armature"] <= 3 * own * 1.01 and finger["armature"] < 0.01 / 100
    kp = SERVO_OMEGA**2 * (own + finger["armature"])
    assert abs(finger["kp"] - kp) / kp < 0.01
    assert {"armature", "kp"} <= set(finger["estimated"])
    assert any("would swamp it" in ln and "servo kp" in ln for ln in done.lines)


@pytest.mark.slow
def test_bolted_and_standing_humanoids_pass_their_checks(tmp_path, kit_factory):
    """The invariant on the small humanoid: with default flags it floats and stands, with
    --fixed-base it is bolted at the pelvis; either kit passes every check (the build
    raises on a failed one)."""
    path = write(tmp_path, _biped(fold=True), "folded")
    for floating in (None, False):
        done = import_robot(path, tmp_path / f"out_{floating}", floating=floating)
        result = kit_factory(str(done.spec_path))
        assert all(f.ok for f in result.findings)


def test_home_off_the_zero_pose_is_reported(tmp_path):
    """A joint whose range leaves out 0 starts mid-range: one line says so; a joint at the
    URDF's zero pose gets none."""
    body = _arm()  # shoulder first, then elbow: only the elbow's range leaves out 0
    at = body.index('name="elbow"')
    body = body[:at] + body[at:].replace('lower="-1.0" upper="1.0"', 'lower="0.5" upper="1.5"')
    done = import_robot(write(tmp_path, body, "offset"), tmp_path / "out")
    spec = yaml.safe_load(done.spec_path.read_text())
    assert spec["poses"]["home"] == [0.0, 1.0]
    lines = [ln for ln in done.lines if "the URDF's zero pose is outside it" in ln]
    assert len(lines) == 1 and "joint[elbow]" in lines[0] and "home: 1," in lines[0]


def test_wheels_are_no_legs(tmp_path):
    """Two wheels below a frame on continuous joints: a two-wheeler does not stand, so the base
    stays fixed; the same links on revolute joints are legs."""
    body = box("frame", "0.6 0.1 0.1", mass=5.0)
    for name, x in (("front", "0.3"), ("rear", "-0.3")):
        body += box(name, "0.05 0.05 0.4", "0 0 -0.2", 1.0)
        body += joint(name, "continuous", "frame", name, f"{x} 0 -0.05")
    done = import_robot(write(tmp_path, body, "two_wheeler"), tmp_path / "two_wheeler")
    assert any("fixed base:" in line for line in done.lines)
    legs = body.replace('type="continuous"', 'type="revolute"')
    done = import_robot(write(tmp_path, legs, "legs"), tmp_path / "legs")
    assert any("floating base: 2 limbs" in line for line in done.lines)
