"""`simkit import --floating-base` (issue 15), second round: a Y-up robot is turned upright,
a URDF without any geometry gets estimated boxes, alike joints of all legs move together
(a quadruped), and the standing height is exact for tilted round shapes. Small handwritten URDFs."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from simkit.importer import import_robot
from simkit.spec.validate import load_spec

INERTIA = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'


def _link(name: str, size: str | None, xyz: str = "0 0 0", mass: float = 1.0) -> str:
    geometry = f'<origin xyz="{xyz}"/><geometry><box size="{size}"/></geometry>'
    solid = f"<visual>{geometry}</visual><collision>{geometry}</collision>" if size else ""
    return (
        f'<link name="{name}"><inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
        f"{INERTIA}</inertial>{solid}</link>"
    )


def _joint(name, parent, child, xyz, axis, lower="-1", upper="1") -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/>'
        f'<child link="{child}"/><origin xyz="{xyz}"/><axis xyz="{axis}"/>'
        f'<limit lower="{lower}" upper="{upper}" effort="50" velocity="2"/></joint>'
    )


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "robot.urdf"
    path.write_text(text, encoding="utf-8")
    return path


def _y_up_biped() -> str:
    """A body on two two-link legs and a head, drawn Y-up: legs along -y, head along +y."""
    text = '<robot name="ybiped">' + _link("body", "0.2 0.1 0.3")
    text += _link("head", "0.1 0.1 0.1", "0 0.1 0", 0.5)
    text += _joint("neck", "body", "head", "0 0.06 0", "0 1 0")
    for side, z in (("left", 0.05), ("right", -0.05)):
        text += _link(f"{side}_thigh", "0.05 0.25 0.05", "0 -0.125 0")
        text += _link(f"{side}_shin", "0.05 0.25 0.05", "0 -0.125 0")
        text += _joint(f"{side}_hip", "body", f"{side}_thigh", f"0 -0.06 {z}", "0 0 1")
        text += _joint(f"{side}_knee", f"{side}_thigh", f"{side}_shin", "0 -0.25 0", "0 0 1")
    return text + "</robot>"


def test_y_up_biped_is_turned_upright(tmp_path):
    done = import_robot(_write(tmp_path, _y_up_biped()), tmp_path / "out", floating=True)
    spec, _doc = load_spec(done.spec_path)
    base = spec.joints[0]
    assert base.type == "floating"
    assert base.rpy == pytest.approx((math.pi / 2, 0.0, 0.0), abs=1e-5)
    assert "rpy" in base.estimated and "xyz" in base.estimated
    assert any("floating base turned rpy 1.571 0 0" in line for line in done.lines)
    assert list(spec.poses["home"]) == [0.0] * 5
    # standing on its feet: the hips 0.06 m and the legs 0.5 m below the base origin
    assert base.xyz[2] == pytest.approx(0.56, abs=1e-4)


def test_z_up_robot_keeps_its_orientation(tmp_path):
    """The same biped drawn Z-up (legs along -z) is not turned."""
    urdf = (
        '<robot name="zbiped">'
        + _link("body", "0.2 0.3 0.1")
        + _link("left_leg", "0.05 0.05 0.5", "0 0 -0.3")
        + _link("right_leg", "0.05 0.05 0.5", "0 0 -0.3")
        + _joint("left_hip", "body", "left_leg", "0 0.1 -0.06", "0 1 0")
        + _joint("right_hip", "body", "right_leg", "0 -0.1 -0.06", "0 1 0")
        + "</robot>"
    )
    done = import_robot(_write(tmp_path, urdf), tmp_path / "out", floating=True)
    spec, _doc = load_spec(done.spec_path)
    assert not any(spec.joints[0].rpy or ())
    assert not any("floating base turned" in line for line in done.lines)


def test_estimated_box_holds_the_mass_up_to_its_cap():
    from simkit.importer.translate.solids import DENSITY, MAX_SIDE, MIN_SIDE, estimated_box

    segment = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -0.3], [0.0, 0.0, -0.1]])
    light = estimated_box(0.6, segment)  # 0.6 kg over 0.3 m: about 3.6 cm thick
    assert np.prod(light["size"]) == pytest.approx(0.6 / DENSITY, rel=1e-4)
    assert light["xyz"] == [0.0, 0.0, -0.15]
    thickness = light["size"][0]
    assert MIN_SIDE < thickness < MAX_SIDE
    assert light["size"] == pytest.approx([thickness, thickness, 0.3 + thickness])
    heavy = estimated_box(30.0, segment)  # would be 28 cm thick: capped
    assert heavy["size"] == pytest.approx([MAX_SIDE, MAX_SIDE, 0.3 + MAX_SIDE])


def test_urdf_without_geometry_gets_estimated_boxes(tmp_path):
    urdf = (
        '<robot name="bare"><link name="base_link"/>'
        + _link("body", None, "0 0 0.05", 10.0)
        + _link("leg", None, "0 0 -0.2", 2.0)
        + '<joint name="waist" type="fixed"><parent link="base_link"/><child link="body"/>'
        "</joint>" + _joint("hip", "body", "leg", "0 0 -0.1", "0 1 0") + "</robot>"
    )
    done = import_robot(_write(tmp_path, urdf), tmp_path / "out", floating=True)
    spec, _doc = load_spec(done.spec_path)
    links = {link.name: link for link in spec.links}
    for name in ("body", "leg"):
        link = links[name]
        assert "solid" in link.estimated
        assert link.collision == "primitives"
        assert link.solid[0].shape == "box" and link.collision_primitives[0].shape == "box"
    # the leg's box spans its origin (the hip) to its CoM 0.2 m down
    leg = links["leg"].solid[0]
    assert leg.size[2] > 0.2 and leg.xyz[2] == pytest.approx(-0.1)
    assert "solid" not in links["base_link"].estimated  # massless: no box
    assert sum("no <visual> or <collision> in the URDF: 2 links" in x for x in done.lines) == 1


def _quadruped() -> str:
    """A body on four legs whose thighs' tops sit 1 cm inside it (5 mm across its edge) at 0;
    each hip abduction
    joint turns about +x on both sides (the URDF does not mirror it), so only the four
    spread together, left and right opposite, part them with the feet level."""
    text = '<robot name="quad">' + _link("body", "0.6 0.3 0.1", mass=5.0)
    for leg, (x, y) in {"lf": (0.25, 0.17), "rf": (0.25, -0.17), "lh": (-0.25, 0.17),
                        "rh": (-0.25, -0.17)}.items():  # fmt: skip
        text += _link(f"{leg}_hip", "0.02 0.02 0.02", mass=0.2)
        text += _link(f"{leg}_thigh", "0.05 0.05 0.4", "0 0 -0.2", 0.5)
        text += _joint(f"{leg}_haa", "body", f"{leg}_hip", f"{x} {y} -0.04", "1 0 0", "-0.8", "0.8")
        text += _joint(f"{leg}_hfe", f"{leg}_hip", f"{leg}_thigh", "0 0 0", "0 1 0")
    return text + "</robot>"


def test_alike_hip_joints_spread_together(tmp_path):
    done = import_robot(_write(tmp_path, _quadruped()), tmp_path / "out", floating=True)
    spec, _doc = load_spec(done.spec_path)
    names = [j.name for j in spec.joints if j.type == "revolute"]
    home = dict(zip(names, spec.poses["home"], strict=True))
    assert home["lf_haa"] > 0.3 and home["lh_haa"] == home["lf_haa"]  # left legs outward
    assert home["rf_haa"] == home["rh_haa"] == -home["lf_haa"]  # mirrored on the right
    assert all(home[f"{leg}_hfe"] == 0.0 for leg in ("lf", "rf", "lh", "rh"))
    # the feet level: the base placed from the spread thighs' lowest corners
    expected = 0.04 + 0.4 * math.cos(home["lf_haa"]) + 0.025 * math.sin(home["lf_haa"])
    assert spec.joints[0].xyz[2] == pytest.approx(expected, abs=1e-5)


def test_alike_groups_need_the_same_limits_and_depth(tmp_path):
    import yaml

    from simkit.importer.fixups.alike import groups
    from simkit.model.kinematics import forward
    from simkit.model.resolve import resolve
    from simkit.spec.schema import RobotSpec

    done = import_robot(_write(tmp_path, _quadruped()), tmp_path / "out", floating=True)
    text = done.spec_path.read_text(encoding="utf-8")
    robot = resolve(RobotSpec.model_validate(yaml.safe_load(text)), text.encode(), "q.yaml")
    found = groups(robot, forward(robot, None))
    names = [sorted(j.name for j in members) for members, _side in found]
    assert names == [
        ["lf_haa", "lh_haa", "rf_haa", "rh_haa"],
        ["lf_hfe", "lh_hfe", "rf_hfe", "rh_hfe"],
    ]
    sides = {j.name: s for j, s in zip(found[0][0], found[0][1], strict=True)}
    assert sides == {"lf_haa": 1.0, "rf_haa": -1.0, "lh_haa": 1.0, "rh_haa": -1.0}


@pytest.mark.parametrize("kind", ["cylinder", "capsule", "sphere"])
def test_lowest_point_of_a_tilted_round_shape_is_exact(kind):
    """A shape tilted 0.7 rad: its lowest point, not its bounding box's corner."""
    from types import SimpleNamespace

    from simkit.importer.fixups.standing import lowest, points
    from simkit.model.kinematics import rpy_matrix, transform

    shape = SimpleNamespace(kind=kind, radius=0.02, length=0.3, xyz=(0.1, 0.0, 0.0),
                            rpy=(0.0, 0.3, 0.0))  # fmt: skip
    pose = transform((0.0, 0.0, 1.0), rpy_matrix((0.7, 0.0, 0.0)))
    rotation = pose[:3, :3] @ rpy_matrix(shape.rpy)
    centre = pose[:3, :3] @ np.array(shape.xyz) + pose[:3, 3]
    if kind == "sphere":
        expected = centre[2] - shape.radius
    else:  # the rims of both ends (a capsule: its end spheres' centres, minus the radius)
        angles = np.linspace(0, 2 * np.pi, 3601)
        radius = 0.0 if kind == "capsule" else shape.radius
        ring = np.stack([np.cos(angles), np.sin(angles), 0 * angles], axis=1) * radius
        half = np.array([0.0, 0.0, shape.length / 2])
        rims = np.vstack([ring + half, ring - half]) @ rotation.T + centre
        expected = float(rims[:, 2].min()) - (shape.radius if kind == "capsule" else 0.0)
    got = lowest(shape, pose, Path("."))
    assert got == pytest.approx(expected, abs=1e-6)
    corners = points(shape, Path(".")) @ pose[:3, :3].T + pose[:3, 3]
    assert float(corners[:, 2].min()) < got - 1e-3  # the corners reach below it
