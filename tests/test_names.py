"""Names exactly as the source documents give them, in every output (issue 12).

- Rosie (000_5f76ade803e16979.txt, "Frames and conventions": "J1 to J6 connect base_link,
  link_1 ... link_6"): joints J1..J6 everywhere.
- ECN 2R (002_e760a3794accbbd5.txt, section 3 step 5: "link 0 is defined as base_link";
  section 5: joint1_position_controller): base_link, and the report's controller names.
- Asimov (001_71a395c46b8a5939.txt): every body, joint, geom, site, sensor, camera and material
  the page names.
- GLB: node names equal URDF link names, for every robot.
"""

from __future__ import annotations

import csv
import json
import struct
import subprocess
import sys
import xml.etree.ElementTree as ET

import mujoco
import pytest

from simkit.kitio import layout

pytestmark = pytest.mark.slow

ROBOTS = ["rosie_600", "rosie_1000", "rosie_1400", "ecn_2r", "asimov"]
ROSIE = ["rosie_600", "rosie_1000", "rosie_1400"]
J = ["J1", "J2", "J3", "J4", "J5", "J6"]
ROSIE_LINKS = ["base_footprint", "base_link", *(f"link_{i}" for i in range(1, 7)), "tool0"]


def _urdf(kit, name: str) -> ET.Element:
    return ET.parse(kit / "urdf" / f"{name}.urdf").getroot()


def _glb(path) -> dict:
    """The glTF JSON chunk of a GLB."""
    data = path.read_bytes()
    (length,) = struct.unpack("<I", data[12:16])
    return json.loads(data[20 : 20 + length])


def _model(kit, name: str) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(kit / "mjcf" / f"{name}.xml"))


def _names(model, kind: str, count: int) -> list[str]:
    return [getattr(model, kind)(i).name for i in range(count)]


@pytest.mark.parametrize("robot", ROSIE)
def test_rosie_joints_are_j1_to_j6_everywhere(kit_factory, robot):
    kit = kit_factory(robot).kit_dir
    urdf = _urdf(kit, robot)
    assert [j.get("name") for j in urdf.iter("joint") if j.get("type") == "revolute"] == J
    assert [link.get("name") for link in urdf.iter("link")] == ROSIE_LINKS
    model = _model(kit, robot)
    assert _names(model, "joint", model.njnt) == J
    assert _names(model, "actuator", model.nu) == J
    srdf = ET.parse(kit / "srdf" / f"{robot}.srdf").getroot()
    group = next(g for g in srdf.iter("group") if g.get("name") == "manipulator")
    chain = group.find("chain")
    if chain is None:
        assert [j.get("name") for j in group.iter("joint")] == J
    for state in srdf.iter("group_state"):
        assert [j.get("name") for j in state.iter("joint")] == J
    usd = (kit / layout.usd_payload(robot, "physics.usda")).read_text()  # the joints' layer
    assert [f'PhysicsRevoluteJoint "{n}"' in usd for n in J] == [True] * 6
    glb = _glb(kit / "glb" / f"{robot}.glb")
    extras = [n["extras"]["joint"]["name"] for n in glb["nodes"] if "joint" in n.get("extras", {})]
    assert [e for e in extras if e != "base_joint"] == J
    doc = json.loads((kit / "robot.json").read_text())
    assert [j["name"] for j in doc["joints"]] == J
    assert doc["benchmarks"]["kit_model_check"]["joints"] == J
    cases = json.loads((kit / "ik_cases.json").read_text())
    assert [j["name"] for j in cases["chain"]["joints"]] == J
    bench = doc["benchmarks"]["trajectory_files"]["cycle_1kg"]
    with (kit / bench["csv"]).open() as handle:
        header = next(csv.reader(handle))
    assert header[1:7] == [f"q_{n}" for n in J] and header[7:13] == [f"qd_{n}" for n in J]
    assert json.loads((kit / bench["json"]).read_text())["joints"] == J
    readme = (kit / "README.md").read_text()
    for n in J:
        assert f"\n| {n} | " in readme
    assert "position servos on J1..J6" in readme and "# J1..J6" in readme
    proc = subprocess.run(
        [sys.executable, "examples/fk_ik.py"], cwd=kit, capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr
    assert "joints J1, J2, J3, J4, J5, J6" in proc.stdout


def test_ecn_2r_link_0_is_base_link_and_controllers_keep_the_report_names(kit_factory):
    kit = kit_factory("ecn_2r").kit_dir
    urdf = _urdf(kit, "ecn_2r")
    assert [link.get("name") for link in urdf.iter("link")] == [
        "world",
        "base_link",
        "link_1",
        "link_2",
        "tip",
    ]
    world_joint = next(j for j in urdf.iter("joint") if j.get("name") == "world_joint")
    assert world_joint.find("child").get("link") == "base_link"  # the report's snippet
    model = _model(kit, "ecn_2r")
    assert _names(model, "body", model.nbody) == ["world", "base_link", "link_1", "link_2"]
    assert _names(model, "joint", model.njnt) == ["joint_1", "joint_2"]
    text = (kit / "config" / "controllers.yaml").read_text()
    for name in ("joint1_position_controller", "joint2_position_controller"):
        assert f"\n{name}:" in text
    for name in ("joint1_effort_controller", "joint2_effort_controller"):
        assert f"\n{name}:" in text
    assert '"link_0"' not in (kit / "robot.json").read_text()
    readme = (kit / "README.md").read_text()
    assert "gazebo.launch.py control:=effort" in readme
    assert "`joint1_position_controller`" in readme


#: 001_71a395c46b8a5939.txt: the names the page gives.
ASIMOV = {
    "body": [
        "pelvis_link",
        *(
            f"{side}_{part}_link"
            for side in ("left", "right")
            for part in (
                "hip_pitch",
                "hip_roll",
                "hip_yaw",
                "knee",
                "ankle_pitch",
                "ankle_roll",
                "toe",
            )
        ),
    ],
    "joint": [
        "floating_base_joint",
        *(
            f"{side}_{part}_joint"
            for side in ("left", "right")
            for part in (
                "hip_pitch",
                "hip_roll",
                "hip_yaw",
                "knee",
                "ankle_pitch",
                "ankle_roll",
                "toe",
            )
        ),
    ],
    "site": ["imu_in_pelvis", "left_foot", "right_foot", "pelvis_link_site"],
    "sensor": ["imu_ang_vel", "imu_lin_vel", "imu_quat", "root_angmom"],
    "camera": ["front_camera"],
    "material": ["visual_grey", "collision_grey", "material", "collision_material", "groundplane"],
    "geom": ["floor", "left_knee_link_collision"],
}


def test_asimov_names_and_knee_capsule_as_the_page_gives_them(kit_factory):
    kit = kit_factory("asimov").kit_dir
    model = mujoco.MjModel.from_xml_path(str(kit / "mjcf" / "asimov_scene.xml"))
    counts = {
        "body": model.nbody,
        "joint": model.njnt,
        "site": model.nsite,
        "sensor": model.nsensor,
        "camera": model.ncam,
        "material": model.nmat,
        "geom": model.ngeom,
    }
    for kind, names in ASIMOV.items():
        have = set(_names(model, kind, counts[kind]))
        assert set(names) <= have, (kind, sorted(set(names) - have))
    assert model.texture("groundplane").id >= 0
    xml = ET.parse(kit / "mjcf" / "asimov.xml").getroot()
    knee = next(g for g in xml.iter("geom") if g.get("name") == "left_knee_link_collision")
    assert knee.get("fromto") == "0 0 0 0 0 -0.25" and knee.get("class") == "body_capsule"
    readme = (kit / "README.md").read_text()
    assert "`sim-model/xmls/asimov.xml` is `mjcf/asimov.xml` in this kit" in readme.replace(
        "\n", " "
    )
    assert "model = mujoco.MjModel.from_xml_path('mjcf/asimov.xml')" in readme


@pytest.mark.parametrize("robot", ROBOTS)
def test_glb_node_names_are_the_urdf_link_names(kit_factory, robot):
    kit = kit_factory(robot).kit_dir
    links = [link.get("name") for link in _urdf(kit, robot).iter("link")]
    nodes = [node["name"] for node in _glb(kit / "glb" / f"{robot}.glb")["nodes"]]
    assert nodes[0] == f"{robot}_y_up"  # the Y-up turn, not a link
    # one node per URDF link (frames included), named exactly as the link; a loader may still
    # rename on load (trimesh turns a node "world" into "world_1": its own root is "world")
    assert sorted(nodes[1:]) == sorted(links) and len(nodes) == len(links) + 1
