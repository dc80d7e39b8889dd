"""Fast unit tests of the byte helpers, the spec's tree order, resolve and mass properties
(no kit builds: the `pytest -m "not slow"` tier)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from simkit.kitio import layout
from simkit.kitio.fmt import num, rounded, vec
from simkit.model.inertia import from_solid, principal_axes, volume_integrals
from simkit.model.resolve import resolve
from simkit.model.robot import Mesh
from simkit.spec.schema import JointSpec, RobotSpec, depth_first


def test_num_significant_digits_and_zero():
    assert num(1.0) == "1"
    assert num(-0.0) == "0"
    assert num(1e-13) == "0"
    assert num(math.pi) == "3.141592654"
    assert vec([0.5, -2, 1e-15]) == "0.5 -2 0"
    with pytest.raises(ValueError):
        num(float("nan"))


@given(st.floats(-1e6, 1e6, allow_nan=False))
def test_rounded_is_what_num_prints(x):
    assert num(rounded(x)) == num(x)


def test_layout_paths_are_relative_posix():
    assert layout.kit_dir_name("rosie_1000") == "rosie_1000_description"
    assert layout.zip_name("rosie_1000") == "rosie-1000-sim-kit.zip"
    assert layout.collision_mesh("link_3", 2) == "meshes/collision/link_3_02.obj"
    assert layout.relative("urdf/x.urdf", "meshes") == "../meshes"
    for path in (layout.urdf("r"), layout.mjcf("r"), layout.usd("r"), layout.glb("r")):
        assert not path.startswith("/") and ".." not in path and "\\" not in path


def _joint(name: str, parent: str, child: str) -> JointSpec:
    return JointSpec(name=name, parent=parent, child=child, lower=-1, upper=1)


def test_depth_first_keeps_chains_contiguous_and_sibling_order():
    joints = [
        _joint("a", "root", "l1"),
        _joint("b", "root", "r1"),
        _joint("a2", "l1", "l2"),
        _joint("b2", "r1", "r2"),
    ]
    assert [j.name for j in depth_first(joints, "root")] == ["a", "a2", "b", "b2"]


def test_depth_first_handles_a_deep_chain():
    joints = [_joint(f"j{i}", f"l{i}", f"l{i + 1}") for i in range(5000)]
    assert len(depth_first(joints, "l0")) == 5000


def _box(x: float, y: float, z: float) -> Mesh:
    corners = np.array([[i, j, k] for i in (0, x) for j in (0, y) for k in (0, z)], float)
    faces = [[0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3], [0, 4, 5], [0, 5, 1],
             [2, 3, 7], [2, 7, 6], [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5]]  # fmt: skip
    return Mesh.of(corners, np.array(faces))


def test_box_mass_properties_match_the_closed_form():
    x, y, z, mass = 0.2, 0.3, 0.5, 6.0
    volume, centroid, _ = volume_integrals(_box(x, y, z))
    assert volume == pytest.approx(x * y * z)
    assert centroid == pytest.approx([x / 2, y / 2, z / 2])
    inertial = from_solid(_box(x, y, z), mass)
    ixx, iyy, izz, ixy, ixz, iyz = inertial.inertia
    assert (ixx, iyy, izz) == pytest.approx(
        [mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12, mass * (x * x + y * y) / 12]
    )
    assert max(abs(ixy), abs(ixz), abs(iyz)) < 1e-12


def test_principal_axes_reconstruct_the_tensor():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(3, 3))
    tensor = a @ a.T + 3 * np.eye(3)
    values, rot = principal_axes(tensor)
    assert np.linalg.det(rot) == pytest.approx(1.0)
    assert rot @ np.diag(values) @ rot.T == pytest.approx(tensor)


def test_resolve_converts_degrees_and_orders_joints():
    spec = RobotSpec.model_validate(
        {
            "name": "two",
            "title": "Two",
            "root": "world",
            "poses_deg": {"home": [90, 0]},
            "links": [
                {"name": "b", "mass": 1.0, "solid": [{"shape": "sphere", "radius": 0.1}]},
                {"name": "a", "mass": 1.0, "solid": [{"shape": "sphere", "radius": 0.1}]},
                {"name": "base", "mass": 1.0, "solid": [{"shape": "sphere", "radius": 0.1}]},
            ],
            "joints": [
                {"name": "j2", "parent": "a", "child": "b", "lower_deg": -45, "upper_deg": 45},
                {"name": "fix", "type": "fixed", "parent": "world", "child": "base"},
                {"name": "j1", "parent": "base", "child": "a", "lower_deg": -180, "upper": 3.0},
            ],
        }
    )
    robot = resolve(spec, b"spec", "two.yaml")
    assert [j.name for j in robot.joints] == ["fix", "j1", "j2"]
    assert [link.name for link in robot.links] == ["base", "a", "b"]
    assert robot.joint("j2").lower == pytest.approx(-math.pi / 4)
    assert robot.joint("j1").upper == 3.0
    assert robot.pose("home") == pytest.approx((math.pi / 2, 0.0))


def test_canonical_faces_ignores_the_starting_corner_and_order():
    """A hull listed from other corners, in another order, is one mesh (one cache key)."""
    import numpy as np

    from simkit.derive.per_link import canonical_faces
    from simkit.kitio.cache import digest
    from simkit.model.robot import Mesh

    vertices = np.eye(4, 3)
    faces = np.array([[0, 1, 2], [0, 3, 1], [1, 3, 2], [0, 2, 3]])
    shuffled = np.array([[3, 1, 0], [2, 0, 1], [2, 3, 0], [1, 3, 2]])  # same triangles
    a = canonical_faces(Mesh.of(vertices, faces))
    b = canonical_faces(Mesh.of(vertices, shuffled))
    assert digest(a) == digest(b)
    assert sorted(map(tuple, a.faces)) == sorted(map(tuple, faces))


def test_given_hull_comes_from_the_cache_by_file_content(tmp_path):
    """A given collision mesh's hull is computed once per file content and placement; the
    cached hull is the computed one, and new bytes give a new hull."""
    from simkit.derive.per_link import HULL_STEP, _given_hull, _shape_hull
    from simkit.kitio.cache import Cache, digest
    from simkit.kitio.stl import to_stl
    from simkit.model.robot import Shape

    cube = Mesh.of(
        np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float),
        np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]),
    )  # fmt: skip
    (tmp_path / "c.stl").write_bytes(to_stl(cube, "c"))
    shape = Shape("mesh", (0.0, 0.0, 0.1), (0.0, 0.0, 0.0), file="c.stl", scale=0.5)
    cache = Cache.at(tmp_path / "cache")
    first = _given_hull(shape, tmp_path, cache)
    assert len(list((tmp_path / "cache").rglob(f"*{HULL_STEP}*"))) >= 1
    again = _given_hull(shape, tmp_path, cache)
    assert digest(again) == digest(first) == digest(_shape_hull(shape, tmp_path))
    assert np.asarray(first.vertices)[:, 2].max() == pytest.approx(0.6)
    (tmp_path / "c.stl").write_bytes(to_stl(Mesh.of(cube.vertices * 2, cube.faces), "c"))
    assert np.asarray(_given_hull(shape, tmp_path, cache).vertices)[:, 2].max() == (
        pytest.approx(1.1)
    )
