"""Importer repairs found on example-robot-data (issue 15): names simkit cannot use, masses
below the spec's minimum, a home pose in self-contact, the tool's chain first; and the exact
convexity of collision pieces and of the FK reference against the kit's own numbers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from simkit.importer import import_robot
from simkit.spec.validate import load_spec

BOX = '<geometry><box size="{0} {0} {1}"/></geometry>'


def _link(name: str, mass: float = 1.0, size: str = "0.04 0.2", z: float = 0.1) -> str:
    shape = BOX.format(*size.split())
    return (
        f'<link name="{name}"><inertial><mass value="{mass}"/>'
        '<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>'
        f'<visual><origin xyz="0 0 {z}"/>{shape}</visual>'
        f'<collision><origin xyz="0 0 {z}"/>{shape}</collision></link>'
    )


def _joint(name: str, parent: str, child: str, z: float, lower: float, upper: float) -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 {z}"/><axis xyz="1 0 0"/>'
        f'<limit lower="{lower}" upper="{upper}" effort="20" velocity="2"/></joint>'
    )


def _import(tmp_path: Path, body: str, name: str = "r") -> tuple[dict, str]:
    urdf = tmp_path / f"{name}.urdf"
    urdf.write_text(f'<?xml version="1.0"?>\n<robot name="{name}">\n{body}\n</robot>\n')
    done = import_robot(urdf, tmp_path / "out")
    load_spec(done.spec_path)  # the written spec passes simkit's own validation
    return yaml.safe_load(done.spec_path.read_text()), "\n".join(done.lines)


def test_names_simkit_cannot_use_are_renamed_with_every_reference(tmp_path):
    body = "\n".join(
        [
            _link("base"),
            _link("link_1.0"),
            _link("link_1.0_visual"),  # what simkit names link_1.0's visual, once renamed
            _joint("joint_1.0", "base", "link_1.0", 0.2, -1, 1),
            _joint("j2", "link_1.0", "link_1.0_visual", 0.2, -1, 1),
        ]
    )
    spec, lines = _import(tmp_path, body)
    names = [link["name"] for link in spec["links"]]
    assert names == ["base", "link_1_0", "link_1_0_visual_link"]
    joints = {j["name"]: j for j in spec["joints"]}
    assert joints["joint_1_0"]["child"] == "link_1_0"
    assert joints["j2"]["parent"] == "link_1_0" and joints["j2"]["child"] == names[2]
    assert spec["tool_frame"] == "link_1_0_visual_link"
    assert "r.urdf:4: link[link_1.0]: changed: renamed to 'link_1_0'" in lines


def test_a_mass_below_the_minimum_is_raised_with_its_inertia(tmp_path):
    body = _link("base") + _link("tip", mass=1e-6) + _joint("j", "base", "tip", 0.2, -1, 1)
    spec, lines = _import(tmp_path, body)
    tip = spec["links"][1]
    assert tip["mass"] == 1e-4 and tip["inertia"]["ixx"] == 0.1  # 1e-3 * (1e-4 / 1e-6)
    assert set(tip["estimated"]) == {"mass", "inertia"}
    assert "mass 1e-06 kg is too small to simulate: 0.0001 kg" in lines


def test_home_in_self_contact_moves_the_joints_between_the_links(tmp_path):
    """An arm 0.2 m long passes through a post fixed on the base at 0; turning the arm clears
    it. A second arm, free at 0, stays at 0."""
    body = "\n".join(
        [
            _link("base", size="0.1 0.02", z=0.0),
            _link("post", size="0.02 0.02", z=0.0),
            _link("arm", size="0.02 0.2", z=0.1),
            _link("other", size="0.02 0.1", z=0.05),
            '<joint name="post_joint" type="fixed"><parent link="base"/><child link="post"/>'
            '<origin xyz="0 0 0.15"/></joint>',
            _joint("ja", "base", "arm", 0.02, -1, 1),
            '<joint name="jo" type="revolute"><parent link="base"/><child link="other"/>'
            '<origin xyz="0.3 0 0.02"/><axis xyz="1 0 0"/>'
            '<limit lower="-1" upper="1" effort="5" velocity="2"/></joint>',
        ]
    )
    spec, lines = _import(tmp_path, body)
    movable = [j["name"] for j in spec["joints"] if j["type"] == "revolute"]
    home = dict(zip(movable, spec["poses"]["home"], strict=True))
    assert home["jo"] == 0.0 and home["ja"] != 0.0
    assert "estimated: home: the links collide at the first guess (0, or mid-range" in lines


def test_home_free_at_zero_stays_zero(tmp_path):
    body = _link("base") + _link("tip") + _joint("j", "base", "tip", 0.2, -1, 1)
    spec, lines = _import(tmp_path, body)
    assert spec["poses"]["home"] == [0.0] and "home:" not in lines


def test_the_tool_chain_comes_first_in_joint_order(tmp_path):
    """A wheel declared before the arm: the first movable joint (the planning group's and FK
    reference's base) must be on the chain to the tool, the deepest link."""
    body = "\n".join(
        [
            _link("base", size="0.3 0.05", z=0.0),
            _link("wheel", size="0.05 0.05", z=0.0),
            _link("upper"),
            _link("lower"),
            '<joint name="wheel_joint" type="continuous"><parent link="base"/>'
            '<child link="wheel"/><origin xyz="0.3 0.3 0"/><axis xyz="0 1 0"/>'
            '<limit effort="5" velocity="2"/></joint>',
            _joint("shoulder", "base", "upper", 0.1, -1, 1),
            _joint("elbow", "upper", "lower", 0.2, -1, 1),
        ]
    )
    spec, _lines = _import(tmp_path, body)
    movable = [j["name"] for j in spec["joints"] if j["type"] != "fixed"]
    assert spec["tool_frame"] == "lower"
    assert movable == ["shoulder", "elbow", "wheel_joint"]


def test_convexity_measure_sees_a_fold_and_convex_mesh_keeps_a_convex_piece():
    """A cube whose top face is folded 1 mm inward is not convex and the check's measure
    reports exactly the fold; a convex piece passes and `convex_mesh` keeps its vertices and
    triangles (in the canonical order)."""
    import manifold3d as mf

    from simkit.check.geometry import _dent
    from simkit.derive.collision import convex_mesh
    from simkit.derive.solids import to_mesh
    from simkit.model.robot import canonical_triangles

    cube = mf.Manifold.cube((0.1, 0.1, 0.1))
    vertices, faces = np.array(to_mesh(cube).vertices), np.array(to_mesh(cube).faces)
    assert _dent(vertices, faces) < 1e-12
    # a sliver-free convex piece keeps its vertices and triangles, in the canonical order
    same = convex_mesh(cube)
    assert np.array_equal(same.vertices, vertices)
    assert np.array_equal(same.faces, canonical_triangles(faces))
    # fold: add a vertex 1 mm below the top face's centre, joined to the top's corners
    top = [i for i, v in enumerate(vertices) if v[2] > 0.05]
    dented = np.vstack([vertices, [0.05, 0.05, 0.099]])
    keep = [f for f in faces.tolist() if not all(i in top for i in f)]
    a, b, c, d = sorted(top, key=lambda i: np.arctan2(*(vertices[i, :2] - 0.05)[::-1]))
    centre = len(dented) - 1
    fan = [[a, b, centre], [b, c, centre], [c, d, centre], [d, a, centre]]
    folded = np.array(keep + fan)
    assert abs(_dent(dented, folded) - 0.001) < 1e-9


def test_fk_reference_tolerance_is_the_written_numbers_precision(tmp_path):
    """Eight origins turned by pi, written with ten digits: their FK differs from the exact
    one by more than 1e-9 but within the rounding bound; a real error of 1e-6 still fails."""
    import json
    import math

    from simkit.check.kit import Kit
    from simkit.check.published_numbers import check_published
    from simkit.kitio.fmt import rounded
    from simkit.model.kinematics import axis_angle, rpy_matrix, transform

    rpy = [math.pi / 2, math.pi, -math.pi / 2]
    joints = [
        {
            "name": f"j{i}",
            "type": "revolute",
            "parent": f"l{i}",
            "child": f"l{i + 1}",
            "origin_xyz": [0.1, 0.0, 0.05],
            "origin_rpy": [rounded(v) for v in rpy],
            "axis": [0.0, 0.0, 1.0],
        }
        for i in range(8)
    ]
    q = [1.0] * 8
    exact = np.eye(4)
    for value in q:  # the pose the spec's exact numbers give
        exact = exact @ transform([0.1, 0.0, 0.05], rpy_matrix(rpy))
        exact = exact @ transform((0, 0, 0), axis_angle([0, 0, 1], value))
    exact = exact @ transform([0.0, 0.0, 0.1], np.eye(3))  # a fixed joint to the tool
    tool = {
        "name": "f",
        "parent": "l8",
        "child": "l9",
        "origin_xyz": [0.0, 0.0, 0.1],
        "origin_rpy": [0.0, 0.0, 0.0],
    }  # fixed joints carry no type
    doc = {"name": "r", "joints": joints, "fixed_joints": [tool], "links": [], "frames": {},
           "files": {}, "base_frame": "l0", "tool_frame": "l9"}  # fmt: skip

    def findings(rotation: np.ndarray) -> dict:
        ref = {"pose": "home", "q": q, "l9": {"xyz": list(exact[:3, 3]), "rotation": rotation}}
        (tmp_path / "robot.json").write_text(json.dumps({**doc, "fk_reference": [ref]}))
        return {f.check: f.ok for f in check_published(Kit(tmp_path))}

    written = Kit(tmp_path)
    (tmp_path / "robot.json").write_text(json.dumps(doc))
    error = np.abs(written.fk(q)[:3, :3] - exact[:3, :3]).max()
    assert error > 1e-9  # a fixed 1e-9 refuses a kit whose numbers are right
    assert all(findings(exact[:3, :3].tolist()).values())
    assert not findings((exact[:3, :3] + 1e-6).tolist())["fk_reference.home.rotation"]


def test_outside_depth_in_blocks_is_the_same_as_at_once(monkeypatch):
    import manifold3d as mf

    from simkit.derive import collision
    from simkit.derive.solids import to_mesh
    from simkit.model import hull as hull_module

    hull = to_mesh(mf.Manifold.sphere(0.1, 48))
    points = np.random.default_rng(0).uniform(-0.2, 0.2, (1000, 3))
    n, d = collision._halfspaces(hull)
    whole = collision.plane_values(points, n, d).max(axis=1)
    monkeypatch.setattr(hull_module, "CHUNK", 7 * len(d))  # 7 points a block
    assert np.array_equal(collision.outside_depth(points, hull), whole)
