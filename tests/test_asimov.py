"""The Asimov kit (issue 6): a floating base, a two-legged tree, passive spring toes, capsule
collision, sensors and scene settings, each checked by name and value against
shared/reference/001_71a395c46b8a5939.txt, plus the standing test and MJX."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest

from simkit.check.kit import Kit
from simkit.check.legged import check_drop, check_stand
from simkit.errors import SpecError
from simkit.pipeline import BuildResult
from simkit.spec.load import load_yaml
from simkit.spec.validate import load_spec, validate

REPO = Path(__file__).resolve().parents[1]
LEGS = ("left", "right")
# Reference "Joint Ranges Summary" (left leg, rad); the right leg is mirrored.
LEFT_RANGES = {
    "hip_pitch": (-2.094395, 1.0),
    "hip_roll": (-0.785, 0.785),
    "hip_yaw": (-0.785, 0.785),
    "knee": (0.0, 1.5),
    "ankle_pitch": (-0.349, 0.5),
    "ankle_roll": (-0.1, 0.1),
    "toe": (-1.047, 0.0),
}
ACTUATED = ("hip_pitch", "hip_roll", "hip_yaw", "knee", "ankle_pitch", "ankle_roll")


@pytest.fixture(scope="module")
def asimov(kit_factory) -> BuildResult:
    return kit_factory("asimov")


@pytest.fixture(scope="module")
def model(asimov) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(asimov.kit_dir / "mjcf/asimov.xml"))


@pytest.fixture(scope="module")
def scene(asimov) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(asimov.kit_dir / "mjcf/asimov_scene.xml"))


@pytest.fixture(scope="module")
def xml(asimov) -> ET.Element:
    return ET.parse(asimov.kit_dir / "mjcf/asimov.xml").getroot()


def _default(xml: ET.Element, name: str) -> ET.Element:
    found = [d for d in xml.iter("default") if d.get("class") == name]
    assert len(found) == 1, name
    return found[0]


def test_build_passes_its_checks(asimov):
    assert asimov.findings and all(f.ok for f in asimov.findings)
    names = {f.check for f in asimov.findings}
    assert {"legged.drop.finite", "legged.stand.height", "mjcf.compile", "urdf.compile"} <= names


def test_joint_ranges_axes_and_toe_spring(model):
    for side, sign in (("left", 1), ("right", -1)):
        for joint, (lo, hi) in LEFT_RANGES.items():
            expected = (lo, hi) if sign > 0 else (-hi, -lo)
            jnt = model.joint(f"{side}_{joint}_joint")
            assert jnt.limited[0] == 1
            np.testing.assert_allclose(jnt.range, expected, atol=1e-12, err_msg=jnt.name)
            assert jnt.armature[0] == pytest.approx(0.01)
    np.testing.assert_allclose(model.joint("right_hip_pitch_joint").range, (-1.0, 2.094395))
    # axes as given (MuJoCo normalises them; the reference's are rounded to 5 digits)
    np.testing.assert_allclose(
        model.joint("left_hip_pitch_joint").axis, (0, 0.70711, -0.70711), atol=1e-5
    )
    np.testing.assert_allclose(
        model.joint("left_toe_joint").axis, (0.010532, 0.99994, 0), atol=1e-5
    )
    np.testing.assert_allclose(
        model.joint("right_toe_joint").axis, (0.010532, -0.99994, 0), atol=1e-5
    )
    for side in LEGS:
        toe = model.joint(f"{side}_toe_joint")
        assert toe.stiffness[0] == pytest.approx(4.5)
        assert model.qpos_spring[toe.qposadr[0]] == 0.0  # springref
        assert toe.damping[0] == pytest.approx(0.5)
        assert toe.frictionloss[0] == pytest.approx(0.02)
        np.testing.assert_allclose(toe.solref, (0.005, 1))
        np.testing.assert_allclose(toe.solimp[:3], (0.99, 0.999, 0.001))
        assert toe.margin[0] == pytest.approx(0.01)
        for joint in ACTUATED:
            assert model.joint(f"{side}_{joint}_joint").damping[0] == 0.0


def test_spec_transcribes_the_reference_exactly():
    """The spec carries the reference's numbers as printed (the MJCF tests compare normalised
    axes with a tolerance, which would not notice a re-typed value)."""
    spec = load_spec(REPO / "robots/asimov.yaml")[0]
    joints = {j.name: j for j in spec.joints}
    assert joints["left_hip_pitch_joint"].axis == (0, 0.70711, -0.70711)
    assert joints["right_hip_pitch_joint"].axis == (0, -0.70711, -0.70711)  # y mirrored
    for side, y in (("left", 0.99994), ("right", -0.99994)):
        toe = joints[f"{side}_toe_joint"]
        assert toe.axis == (0.010532, y, 0)
        assert (toe.stiffness, toe.springref, toe.damping, toe.friction) == (4.5, 0, 0.5, 0.02)
        assert toe.solreflimit == (0.005, 1) and toe.solimplimit == (0.99, 0.999, 0.001)
        assert (toe.margin, toe.armature, toe.actuated) == (0.01, 0.01, False)
    assert all(j.armature == 0.01 for j in spec.joints if j.type != "floating")
    pelvis = spec.links[0]
    assert (pelvis.name, pelvis.mass) == ("pelvis_link", 3.3125)
    assert pelvis.com == (-0.00071228, -3.4719e-07, -0.073826)
    inertia = pelvis.inertia
    assert (inertia.ixx, inertia.iyy, inertia.izz) == (0.0033117, 0.0028238, 0.003564)
    assert joints["floating_base_joint"].xyz == (0, 0, 0.739)


def _tensor(model: mujoco.MjModel, body: str) -> np.ndarray:
    """Inertia about the CoM in the link axes (MuJoCo stores principal moments + iquat)."""
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, model.body(body).iquat)
    rot = rot.reshape(3, 3)
    return rot @ np.diag(model.body(body).inertia) @ rot.T


def test_masses_and_inertias(model):
    pelvis = model.body("pelvis_link")
    assert pelvis.mass[0] == pytest.approx(3.3125)
    np.testing.assert_allclose(pelvis.ipos, (-0.00071228, -3.4719e-07, -0.073826), atol=1e-12)
    np.testing.assert_allclose(
        _tensor(model, "pelvis_link"), np.diag((0.0033117, 0.0028238, 0.003564)), atol=1e-12
    )
    for side in LEGS:
        assert model.body(f"{side}_hip_pitch_link").mass[0] == pytest.approx(0.926)
        assert model.body(f"{side}_knee_link").mass[0] == pytest.approx(2.248)
        assert model.body(f"{side}_ankle_roll_link").mass[0] == pytest.approx(0.613)
        assert model.body(f"{side}_toe_link").mass[0] == pytest.approx(0.112)
        assert _tensor(model, f"{side}_knee_link")[0, 0] == pytest.approx(0.0094)
        assert _tensor(model, f"{side}_ankle_roll_link")[2, 2] == pytest.approx(0.0007)
        assert _tensor(model, f"{side}_toe_link")[0, 0] == pytest.approx(5.54e-5)
    masses = model.body_mass[1:]
    assert masses.min() == pytest.approx(0.112)  # the toe is the lightest segment
    legs = [model.body(f"left_{n}_link").mass[0] for n in (*ACTUATED, "toe")]
    assert max(legs) == pytest.approx(2.248)  # the knee is the heaviest leg segment


def test_floating_base_sites_camera_sensors(model):
    free = model.joint("floating_base_joint")
    assert free.type[0] == mujoco.mjtJoint.mjJNT_FREE
    assert model.body(free.bodyid[0]).name == "pelvis_link"
    assert model.body("pelvis_link").parentid[0] == 0
    np.testing.assert_allclose(model.body("pelvis_link").pos, (0, 0, 0.739))
    np.testing.assert_allclose(model.qpos0[:7], (0, 0, 0.739, 1, 0, 0, 0))
    imu = model.site("imu_in_pelvis")
    np.testing.assert_allclose(imu.pos, (0.04525, 0, -0.08339))
    assert imu.size[0] == pytest.approx(0.01)
    assert model.body(imu.bodyid[0]).name == "pelvis_link"
    for side in LEGS:
        site = model.site(f"{side}_foot")
        np.testing.assert_allclose(site.pos, (0.04, 0, -0.025))
        assert model.body(site.bodyid[0]).name == f"{side}_ankle_roll_link"
    np.testing.assert_allclose(model.site("pelvis_link_site").pos, (0, 0, 0))
    np.testing.assert_allclose(model.site("pelvis_link_site").quat, (1, 0, 0, 0))
    cam = model.camera("front_camera")
    assert cam.mode[0] == mujoco.mjtCamLight.mjCAMLIGHT_TRACK
    assert cam.fovy[0] == pytest.approx(90.0)
    np.testing.assert_allclose(cam.pos, (0, 2, 0.5))
    np.testing.assert_allclose(
        cam.quat, np.array([4.33e-17, 4.33e-17, 0.7071, 0.7071]) / np.sqrt(2 * 0.7071**2), atol=1e-9
    )
    assert model.body(cam.bodyid[0]).name == "pelvis_link"
    assert model.ncam == 2
    site_id, body_id = model.site("imu_in_pelvis").id, model.body("pelvis_link").id
    sensors = {
        "imu_ang_vel": (mujoco.mjtSensor.mjSENS_GYRO, mujoco.mjtObj.mjOBJ_SITE, site_id),
        "imu_lin_vel": (mujoco.mjtSensor.mjSENS_VELOCIMETER, mujoco.mjtObj.mjOBJ_SITE, site_id),
        "imu_quat": (mujoco.mjtSensor.mjSENS_FRAMEQUAT, mujoco.mjtObj.mjOBJ_SITE, site_id),
        "root_angmom": (mujoco.mjtSensor.mjSENS_SUBTREEANGMOM, mujoco.mjtObj.mjOBJ_BODY, body_id),
    }
    assert model.nsensor == len(sensors)
    for name, (kind, objtype, objid) in sensors.items():
        sensor = model.sensor(name)
        assert (sensor.type[0], sensor.objtype[0], sensor.objid[0]) == (kind, objtype, objid), name


def test_scene_settings(model, xml):
    assert model.opt.timestep == pytest.approx(0.002)
    compiler = xml.find("compiler")
    assert compiler.get("angle") == "radian" and compiler.get("meshdir") == "../meshes"
    vis = model.vis
    assert (vis.global_.offwidth, vis.global_.offheight) == (1920, 1080)
    assert (vis.global_.azimuth, vis.global_.elevation) == (-140, -20)
    np.testing.assert_allclose(vis.headlight.diffuse, (0.6, 0.6, 0.6), rtol=1e-6)
    np.testing.assert_allclose(vis.headlight.ambient, (0.1, 0.1, 0.1), rtol=1e-6)
    np.testing.assert_allclose(vis.headlight.specular, (0.9, 0.9, 0.9), rtol=1e-6)
    np.testing.assert_allclose(vis.rgba.haze, (0.15, 0.25, 0.35, 1), rtol=1e-6)
    assert _default(xml, "motor").find("joint").get("damping") == "0"
    visual = _default(xml, "visual").find("geom").attrib
    assert (visual["group"], visual["contype"], visual["conaffinity"]) == ("2", "0", "0")
    assert visual["material"] == "visual_grey"
    for name, radius in (("foot_capsule", "0.01"), ("body_capsule", "0.05")):
        geom = _default(xml, name).find("geom").attrib
        assert (geom["type"], geom["size"]) == ("capsule", radius)
    rgba = {
        "visual_grey": (0.7, 0.7, 0.7, 1),
        "collision_grey": (0.5, 0.5, 0.5, 0.5),
        "material": (0.75294, 0.75294, 0.75294, 1),
        "collision_material": (1, 0.28, 0.1, 0.9),
    }
    for name, value in rgba.items():
        np.testing.assert_allclose(model.material(name).rgba, value, rtol=1e-6)
    ground = model.material("groundplane")
    assert model.texture(ground.texid[mujoco.mjtTextureRole.mjTEXROLE_RGB]).name == "groundplane"
    np.testing.assert_allclose(ground.texrepeat, (5, 5))
    assert ground.texuniform[0] == 1 and ground.reflectance[0] == pytest.approx(0.2)
    tex = model.texture("groundplane")
    assert (tex.width[0], tex.height[0]) == (300, 300)
    texture = xml.find("asset/texture").attrib
    assert (texture["builtin"], texture["mark"], texture["type"]) == ("checker", "edge", "2d")
    assert (texture["rgb1"], texture["rgb2"], texture["markrgb"]) == (
        "0.2 0.3 0.4",
        "0.1 0.2 0.3",
        "0.8 0.8 0.8",
    )
    floor = model.geom("floor")
    assert floor.type[0] == mujoco.mjtGeom.mjGEOM_PLANE and floor.size[2] == pytest.approx(0.05)
    assert model.material(floor.matid[0]).name == "groundplane"
    assert (floor.contype[0], floor.conaffinity[0]) == (1, 1)
    assert model.nlight == 2
    np.testing.assert_allclose(model.light_pos, [(1, 0, 3.5), (0, 0, 4)])
    np.testing.assert_allclose(model.light_dir, [(0, 0, -1), (0, 0, -1)])
    lights = xml.findall("worldbody/light")
    assert [light.get("directional") for light in lights] == ["true", "true"]
    assert (lights[1].get("diffuse"), lights[1].get("specular")) == ("0.6 0.6 0.6", "0.2 0.2 0.2")


def test_collision_capsules_and_excludes(asimov, model):
    cls = {"body": 0.05, "foot": 0.01}
    collision = [i for i in range(model.ngeom) if model.geom_group[i] == 3]
    assert collision and all(model.geom_type[i] == mujoco.mjtGeom.mjGEOM_CAPSULE for i in collision)
    assert {round(float(model.geom_size[i, 0]), 6) for i in collision} == set(cls.values())
    for side in LEGS:
        for link, count in (("ankle_roll_link", 6), ("toe_link", 5)):
            body = model.body(f"{side}_{link}").id
            geoms = [i for i in collision if model.geom_bodyid[i] == body]
            assert len(geoms) == count
            assert all(model.geom_size[i, 0] == pytest.approx(0.01) for i in geoms)
            axes = [model.geom_quat[i] for i in geoms]  # parallel: one orientation
            assert all(np.allclose(q, axes[0]) for q in axes)
        knee = model.geom(f"{side}_knee_link_collision")  # the page's name
        assert knee.size[0] == pytest.approx(0.05) and knee.size[1] == pytest.approx(0.125)
    # visual geoms (group 2) never collide
    visual = [i for i in range(model.ngeom) if model.geom_group[i] == 2]
    assert len(visual) == 15 and not any(
        model.geom_contype[i] or model.geom_conaffinity[i] for i in visual
    )
    doc = json.loads((asimov.kit_dir / "robot.json").read_text())
    links = {link["name"] for link in doc["links"]}
    adjacent = {frozenset((j["parent"], j["child"])) for j in doc["joints"] if j["parent"] in links}
    excluded = {
        frozenset((model.body(b1).name, model.body(b2).name))
        for b1, b2 in zip(
            model.exclude_signature >> 16, model.exclude_signature & 0xFFFF, strict=True
        )
    }
    assert len(adjacent) == 14 and excluded == adjacent


def test_standing_height_and_stand_check(asimov, model):
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    capsules = [
        i for i in range(model.ngeom) if model.geom_group[i] == 3 and model.geom_size[i, 0] < 0.02
    ]
    lowest = min(float(data.geom_xpos[i][2]) - model.geom_size[i, 0] for i in capsules)
    assert lowest == pytest.approx(0.0, abs=1e-6)  # feet on the floor at 0.739 m
    kit = Kit.open(asimov.kit_dir)
    stand = {f.check: f for f in check_stand(kit)}
    assert all(f.ok for f in stand.values())
    assert float(stand["legged.stand.height"].actual) < 0.02
    drop = {f.check: f for f in check_drop(kit)}
    assert drop["legged.drop.finite"].ok and drop["legged.drop.floor"].ok


def test_main_file_has_no_actuators_scene_has_servos(model, scene):
    assert model.nu == 0
    assert scene.nu == 12 and scene.nbody == model.nbody and scene.nsensor == model.nsensor
    for a in range(scene.nu):
        assert scene.actuator_gainprm[a, 0] == pytest.approx(100)  # kp
        assert -scene.actuator_biasprm[a, 2] == pytest.approx(10)  # kv
        np.testing.assert_allclose(scene.actuator_forcerange[a], (-120, 120))
    assert scene.actuator("left_knee_joint").trnid[0] == scene.joint("left_knee_joint").id
    key = scene.key("home")
    np.testing.assert_allclose(key.qpos[:7], (0, 0, 0.739, 1, 0, 0, 0))


def test_urdf_robot_json_readme(asimov):
    import yourdfpy

    urdf = yourdfpy.URDF.load(str(asimov.kit_dir / "urdf/asimov.urdf"), load_meshes=False)
    assert urdf.base_link == "pelvis_link"
    assert "world" not in urdf.link_map and "floating_base_joint" not in urdf.joint_map
    doc = json.loads((asimov.kit_dir / "robot.json").read_text())
    assert doc["floating_base"]["child"] == "pelvis_link"
    assert doc["files"]["mjcf_scene"] == "mjcf/asimov_scene.xml"
    assert not {"fk_reference", "reach", "payload", "repeatability_mm"} & set(doc)
    assert [j["name"] for j in doc["fixed_joints"]] == []
    assert len(doc["joints"]) == 14 and doc["base_frame"] == "pelvis_link"
    readme = (asimov.kit_dir / "README.md").read_text()
    assert "useFixedBase=False" in readme and "stretched" not in readme
    blocks = re.findall(r"```python\n(.*?)```", readme, re.S)
    code = next(b for b in blocks if "mj_resetDataKeyframe" in b)  # after the page's snippets
    out = subprocess.run(
        [sys.executable, "-c", code],
        cwd=asimov.kit_dir,
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    ).stdout
    assert "Number of actuators: 0" in out and "Number of sensors: 4" in out
    assert out.strip().splitlines()[-1].split()[-1].rstrip("]") == "0.739"  # still standing


def test_mjx_accepts_the_model(model):
    mjx = pytest.importorskip("mujoco.mjx", reason="mujoco-mjx (and jax) not installed")
    mx = mjx.put_model(model)
    assert mx.nq == model.nq == 21 and mx.nu == 0


def _spec_with(tmp_path: Path, old: str, new: str) -> Path:
    text = (REPO / "robots/asimov.yaml").read_text()
    assert old in text
    path = tmp_path / "asimov_bad.yaml"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize(
    ("old", "new", "field"),
    [
        (
            "    type: floating\n",
            "    type: fixed\n",
            "floating_base: floating_base needs a joint of type 'floating'",
        ),
        (
            "    xyz: [0, 0, 0.739]\n",
            "    xyz: [0, 0, 0.739]\n    lower: 0\n",
            "joints[0].lower: a floating joint has no limits",
        ),
        (
            "mjcf_class: motor",
            "mjcf_class: motors",
            "joints[1].mjcf_class: unknown MJCF default class",
        ),
        (
            "geom_class: body_capsule",
            "geom_class: body_capsules",
            "collision_primitives[0].geom_class",
        ),
        (
            "{type: gyro, name: imu_ang_vel, site: imu_in_pelvis}",
            "{type: gyro, name: imu_ang_vel}",
            "a gyro sensor needs 'site'",
        ),
        ("objname: imu_in_pelvis", "objname: imu", "mjcf.sensors[2].objname: unknown site 'imu'"),
        ("body: pelvis_link, mode: track", "body: pelvis, mode: track", "mjcf.cameras[0].body"),
        (  # rnea.py integrates a fixed-base tree only
            "seed: 0\n",
            "seed: 0\nfreefall: {pose: home}\n",
            "freefall: the free-fall validation needs a fixed base",
        ),
    ],
)
def test_spec_errors_name_the_field(tmp_path, old, new, field):
    doc = load_yaml(_spec_with(tmp_path, old, new))
    with pytest.raises(SpecError) as err:
        validate(doc)
    assert field in str(err.value)
