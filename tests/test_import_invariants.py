"""An import refuses in one line naming the URDF, or writes a spec that validates and that
MuJoCo compiles (issue 22): an illegal root name, a tiny primitive, an error inside the
import's staging copy, an inertia on the triangle-inequality limit; and checks written for the
seed robots that failed legitimate imports (usd.articulation)."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from simkit.errors import SpecError
from simkit.importer import import_robot
from simkit.spec.schema import InertiaSpec
from simkit.spec.validate import inertia_problem, load_spec, mujoco_refuses

BOX = '<geometry><box size="0.05 0.05 0.2"/></geometry>'


def _link(name: str, inertia: str = "0.001 0.001 0.001", geometry: str = BOX) -> str:
    ixx, iyy, izz = inertia.split()
    return (
        f'<link name="{name}"><inertial><mass value="1"/><inertia ixx="{ixx}" iyy="{iyy}" '
        f'izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>'
        f"<visual>{geometry}</visual><collision>{geometry}</collision></link>"
    )


def _joint(parent: str, child: str, name: str = "j1") -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        '<origin xyz="0 0 0.2"/><axis xyz="1 0 0"/>'
        '<limit lower="-1" upper="1" effort="20" velocity="2"/></joint>'
    )


def _import(tmp_path: Path, *body: str, name: str = "r"):
    urdf = tmp_path / f"{name}.urdf"
    urdf.write_text(
        f'<?xml version="1.0"?>\n<robot name="{name}">\n' + "\n".join(body) + "\n</robot>\n"
    )
    done = import_robot(urdf, tmp_path / "out")
    load_spec(done.spec_path)
    return yaml.safe_load(done.spec_path.read_text()), "\n".join(done.lines)


def test_an_illegal_root_frame_name_is_renamed_with_the_root(tmp_path):
    fixed = '<joint name="f" type="fixed"><parent link="r2/world_ref"/><child link="base"/></joint>'
    spec, lines = _import(
        tmp_path,
        '<link name="r2/world_ref"/>',
        _link("base"),
        _link("arm"),
        fixed,
        _joint("base", "arm"),
    )
    assert spec["root"] == "r2_world_ref"
    assert {j["name"]: j["parent"] for j in spec["joints"]}["f"] == "r2_world_ref"
    assert "link[r2/world_ref]: changed: renamed to 'r2_world_ref'" in lines


def test_a_primitive_below_a_millimetre_is_left_out_with_a_report_line(tmp_path):
    tiny = '<geometry><sphere radius="0.0005"/></geometry>'
    spec, lines = _import(
        tmp_path, _link("base"), _link("arm", geometry=tiny), _joint("base", "arm")
    )
    arm = spec["links"][1]
    assert "solid" not in arm and arm["collision_primitives"] == []
    assert "collision sphere of 0.0005 m is below the 0.001 m a spec simulates" in lines
    whats = {d["what"] for d in spec["source_differences"]}
    assert {"links.arm.visual", "links.arm.collision"} <= whats  # listed for the record


def test_a_spec_refusal_names_the_urdf_line_not_the_staging_copy(tmp_path):
    heavy = _link("arm").replace('<mass value="1"/>', '<mass value="1e5"/>')
    with pytest.raises(SpecError) as caught:
        _import(tmp_path, _link("base"), heavy, _joint("base", "arm"))
    text = str(caught.value)
    assert text.startswith(f"{tmp_path / 'r.urdf'}:4: link[arm]: the imported spec's links[1].mass")
    assert ".import-" not in text and "\n" not in text
    assert not (tmp_path / "out").exists()  # nothing half-written, not even the folder


def _mujoco_compiles(ixx: float, iyy: float, izz: float, off=(0.0, 0.0, 0.0)) -> bool:
    import mujoco

    from simkit.kitio.fmt import vec

    full = vec((ixx, iyy, izz, *off))
    xml = (
        '<mujoco><worldbody><body><joint type="hinge"/>'
        f'<inertial pos="0 0 0" mass="1" fullinertia="{full}"/></body></worldbody></mujoco>'
    )
    try:
        mujoco.MjModel.from_xml_string(xml)
    except ValueError:
        return False
    return True


@pytest.mark.parametrize(
    "moments",
    [(0.1, 0.7, 0.8), (0.7, 0.1, 0.8), (0.001, 0.001, 0.002), (0.1, 0.7, 0.79), (0.3, 0.5, 0.8)],
)
def test_validation_refuses_exactly_the_diagonal_inertias_mujoco_refuses(moments):
    spec = InertiaSpec(ixx=moments[0], iyy=moments[1], izz=moments[2])
    assert mujoco_refuses(spec) is not _mujoco_compiles(*moments)
    assert (inertia_problem(spec) is None) is _mujoco_compiles(*moments)


def test_an_inertia_on_the_limit_is_raised_off_it_and_mujoco_compiles_it(tmp_path):
    spec, lines = _import(
        tmp_path, _link("base"), _link("arm", inertia="0.1 0.7 0.8"), _joint("base", "arm")
    )
    arm = spec["links"][1]
    assert "inertia" in arm["estimated"]
    assert "inertia on the triangle-inequality limit" in lines
    i = arm["inertia"]
    assert _mujoco_compiles(i["ixx"], i["iyy"], i["izz"])
    whats = {d["what"] for d in spec["source_differences"]}
    assert "links.arm.inertia" in whats  # the source check allows it, with the reason


def _props() -> list[str]:
    """A drone: a frame and four props on fixed joints."""
    disc = '<geometry><cylinder radius="0.1" length="0.01"/></geometry>'
    out = [_link("frame")]
    for k, (x, y) in enumerate([(0.2, 0), (-0.2, 0), (0, 0.2), (0, -0.2)]):
        out.append(_link(f"prop{k}", "1e-5 1e-5 1e-5", disc))
        out.append(
            f'<joint name="prop{k}_joint" type="fixed"><parent link="frame"/>'
            f'<child link="prop{k}"/><origin xyz="{x} {y} 0.05"/></joint>'
        )
    return out


@pytest.mark.slow
@pytest.mark.parametrize(
    ("body", "floating"),
    [
        # a cube hinged on a massless `world` root: the parser leaves the cube out of the
        # articulation's bodies though its joint is articulated
        (['<link name="world"/>', _link("cube"), _joint("world", "cube", "hinge")], False),
        # one body fixed to the world (a drone's frame with the default fixed base)
        ([_link("frame")], False),
        # a floating drone with fixed-only props: rigid, nothing to articulate
        (_props(), True),
    ],
    ids=["hinged_cube", "fixed_drone_frame", "floating_drone_props"],
)
def test_usd_articulation_passes_legitimate_small_imports(tmp_path, body, floating):
    from simkit.pipeline import build

    urdf = tmp_path / "p.urdf"
    urdf.write_text('<?xml version="1.0"?>\n<robot name="p">\n' + "\n".join(body) + "\n</robot>\n")
    done = import_robot(urdf, tmp_path / "out", floating=floating)
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert any(f.check == "usd.articulation" and f.ok for f in result.findings)


@pytest.mark.slow
def test_step_products_passes_a_robot_without_any_geometry(tmp_path):
    """A URDF of inertials only (a humanoid's dynamics model): the STEP holds an empty
    assembly, which is no link product missing or extra."""
    from simkit.pipeline import build

    bare = [
        f'<link name="{n}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" '
        'ixy="0" ixz="0" iyz="0"/></inertial></link>'
        for n in ("pelvis", "thigh")
    ]
    urdf = tmp_path / "bare.urdf"
    body = "\n".join([*bare, _joint("pelvis", "thigh", "hip")])
    urdf.write_text(f'<?xml version="1.0"?>\n<robot name="bare">\n{body}\n</robot>\n')
    done = import_robot(urdf, tmp_path / "out")
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    assert any(f.check == "step.products" and f.ok for f in result.findings)
