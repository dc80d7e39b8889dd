"""Self-collision (issue 12): the MuJoCo measures (simulate/self_collision.py), the kit check
(check/self_collision_check.py), robot.json `geometry.self_collision`, flagged IK solutions
and the benchmark's kit-model check with contacts on."""

from __future__ import annotations

import json
import math
import re
import shutil

import mujoco
import numpy as np
import pytest

from simkit.check.kit import Kit
from simkit.check.self_collision import check_self_collision
from simkit.simulate import self_collision as sc

#: Two capsules on a hinge over a fixed post: the arm (0.4 m, r 0.05) swings about y at
#: z = 0.5; positive angles turn it down onto the post (r 0.05, x = 0, top at z = 0.3), over
#: an interval symmetric about straight down (pi / 2); negative angles turn it up, free.
TOY = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="post">
      <geom name="post" type="capsule" fromto="0 0 0 0 0 0.3" size="0.05"/>
      <body name="arm" pos="0 0 0.5">
        <joint name="hinge" axis="0 1 0" range="-3.1 3.1"/>
        <geom name="arm" type="capsule" fromto="0 0 0 0.4 0 0" size="0.05"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def _toy():
    model = mujoco.MjModel.from_xml_string(TOY)
    return model, mujoco.MjData(model), sc.joint_addresses(model, ["hinge"])


def test_contacts_name_the_bodies_and_ignore_the_world():
    model, data, adr = _toy()
    assert sc.contacts(model, data, adr, [0.0]) == []  # arm horizontal; the floor is not "self"
    down = sc.contacts(model, data, adr, [math.pi / 2 + 0.3])  # arm tilted down into the post
    assert [(c.body1, c.body2) for c in down] == [("arm", "post")]
    assert down[0].depth > 0.001


def test_clearance_free_range_and_fraction_of_the_toy_arm():
    model, data, adr = _toy()
    dist, a, b = sc.min_clearance(model, data, adr, [0.0])
    # arm axis at z 0.5, post top at z 0.3: 0.2 m between axes, minus both radii
    assert (a, b) == ("arm", "post") and dist == pytest.approx(0.1, abs=1e-6)
    lo, hi = sc.free_range(model, data, adr, [0.0], 0, -3.1, 3.1)
    assert lo == pytest.approx(-3.1) and 0.2 < hi < math.pi / 2  # stops before the post
    hit = sc.worst(model, data, adr, [hi + sc.RANGE_STEP])
    assert hit.depth > sc.TOLERANCE and (hit.body1, hit.body2) == ("arm", "post")
    frac = sc.contact_fraction(model, data, adr, [-3.1], [3.1], seed=0, samples=4000)
    assert frac == pytest.approx((math.pi - 2 * hi) / 6.2, abs=0.03)  # [hi, pi - hi] collides
    summary = sc.summary(model, ["hinge"], [-3.1], [3.1], [0.0], seed=0, samples=500)
    assert summary["free_ranges"][0]["limited_by_collision"] is True
    assert summary["home_closest_pair"] == ["arm", "post"]


slow = pytest.mark.slow


@slow
@pytest.mark.parametrize("robot", ["rosie_600", "rosie_1000", "rosie_1400", "ecn_2r", "asimov"])
def test_every_kit_passes_the_self_collision_check(kit_factory, robot):
    result = kit_factory(robot)
    found = [f for f in result.findings if f.check.startswith("self_collision.")]
    kit = Kit.open(result.kit_dir)
    moving = [j for j in kit.joints if j["type"] != "fixed"]
    assert len([f for f in found if f.check.startswith("self_collision.sweep.")]) == len(moving)
    assert all(f.ok for f in found), [f.line() for f in found if not f.ok]
    block = kit.doc["geometry"]["self_collision"]
    assert [r["joint"] for r in block["free_ranges"]] == [j["name"] for j in moving]
    assert block["random_samples"] == 10_000 and 0.0 <= block["random_contact_fraction"] < 0.15
    if robot.startswith("rosie"):
        # limits are the collision-free range; the wrist clears the forearm at home
        assert not any(r["limited_by_collision"] for r in block["free_ranges"])
        assert block["home_min_clearance_m"] > 0.015
        j5 = next(j for j in kit.joints if j["name"] == "J5")
        assert j5["upper_deg"] > 90 and j5["lower_deg"] < -90  # the flange passes +-90 deg


@slow
def test_robot_json_self_collision_is_what_mujoco_measures(rosie_1000):
    kit = Kit.open(rosie_1000.kit_dir)
    model = mujoco.MjModel.from_xml_path(str(kit.path(kit.mjcf)))
    names = [j["name"] for j in kit.joints]
    lower, upper = [j["lower"] for j in kit.joints], [j["upper"] for j in kit.joints]
    again = sc.summary(model, names, lower, upper, kit.doc["home"], seed=0, samples=10_000)
    block = kit.doc["geometry"]["self_collision"]
    assert block["random_contact_fraction"] == pytest.approx(again["random_contact_fraction"])
    assert block["home_min_clearance_m"] == pytest.approx(again["home_min_clearance_m"])


def _copy(result, tmp_path):
    kit = tmp_path / result.kit_dir.name
    shutil.copytree(result.kit_dir, kit)
    return kit


@slow
def test_a_colliding_named_pose_fails_naming_the_two_links(rosie_1000, tmp_path):
    kit = _copy(rosie_1000, tmp_path)
    doc = json.loads((kit / "robot.json").read_text())
    doc["poses"]["work"] = [0.0, 0.0, math.radians(100), 0.0, 0.0, 0.0]  # wrist into shoulder
    (kit / "robot.json").write_text(json.dumps(doc))
    bad = [f for f in check_self_collision(Kit.open(kit)) if not f.ok]
    assert [f.check for f in bad] == ["self_collision.poses"]
    assert "pose 'work'" in bad[0].detail and "link_1 and link_4 penetrate" in bad[0].detail
    assert float(bad[0].actual) > 1.0  # mm


@slow
def test_a_tampered_mjcf_fails_naming_the_two_links(rosie_1000, tmp_path):
    kit = _copy(rosie_1000, tmp_path)
    path = kit / "mjcf" / "rosie_1000.xml"
    text = path.read_text()
    # pull the wrist 200 mm back along the forearm, out of its fork: the flange hits link_4
    text, n = re.subn(
        r'<body name="link_5" pos="0.38 0 0"', '<body name="link_5" pos="0.18 0 0"', text
    )
    assert n == 1
    path.write_text(text)
    bad = {f.check: f for f in check_self_collision(Kit.open(kit)) if not f.ok}
    assert "self_collision.poses" in bad and "self_collision.sweep.J5" in bad
    assert "self_collision.sweep.J1" not in bad  # J1 alone moves nothing into anything
    for check in ("self_collision.poses", "self_collision.sweep.J5"):
        assert re.search(r"link_4 and link_6 penetrate \d+\.\d mm", bad[check].detail)
    assert "pose 'work'" in bad["self_collision.poses"].detail


@slow
def test_an_unflagged_colliding_ik_solution_fails(rosie_1000, tmp_path):
    kit = _copy(rosie_1000, tmp_path)
    cases = json.loads((kit / "ik_cases.json").read_text())
    case = next(c for c in cases["cases"] if c["all_solutions"])
    case["all_solutions"][0]["q"] = [0.0, 0.0, math.radians(100), 0.0, 0.0, 0.0]
    (kit / "ik_cases.json").write_text(json.dumps(cases))
    bad = {f.check: f for f in check_self_collision(Kit.open(kit)) if not f.ok}
    assert list(bad) == ["self_collision.ik_flags"]
    assert "not flagged self_collision" in bad["self_collision.ik_flags"].detail
    # flagged with the depth MuJoCo finds, it may stay
    model = mujoco.MjModel.from_xml_path(str(kit / "mjcf" / "rosie_1000.xml"))
    data = mujoco.MjData(model)
    adr = sc.joint_addresses(model, [f"J{i}" for i in range(1, 7)])
    depth = sc.worst(model, data, adr, case["all_solutions"][0]["q"]).depth
    case["all_solutions"][0].update(self_collision=True, self_collision_depth_m=depth)
    (kit / "ik_cases.json").write_text(json.dumps(cases))
    assert all(f.ok for f in check_self_collision(Kit.open(kit)))


@slow
def test_derived_depth_flags_listed_solutions(rosie_1000):
    from simkit.derive.ik_cases import _listed
    from simkit.derive.self_contact import depth_function
    from simkit.model.ik import Solution
    from simkit.pipeline import model_from_spec

    robot = model_from_spec("rosie_1000")
    names = [f"J{i}" for i in range(1, 7)]
    depth = depth_function(robot, names)
    assert depth([0.0] * 6) == 0.0
    folded = [0.0, 0.0, math.radians(100), 0.0, 0.0, 0.0]
    assert depth(folded) > 0.01

    listed = _listed(Solution(tuple(folded), "front", "down", "noflip"), depth)
    assert listed["self_collision"] is True
    assert listed["self_collision_depth_m"] == pytest.approx(depth(folded))


@slow
def test_kit_model_check_runs_with_contacts(rosie_1000):
    from simkit.simulate.benchmark import kit_model_check, mesh_assets

    kit = Kit.open(rosie_1000.kit_dir)
    text = kit.path(kit.mjcf).read_text()
    assets = mesh_assets(kit.root)
    payload = {"mass": 0.0}
    names = [f"J{i}" for i in range(1, 7)]
    zero = np.zeros((1, 6))
    free = kit_model_check(text, names, "link_6", payload, zero, zero, zero, assets)
    folded = np.radians([[0.0, 0.0, 100.0, 0.0, 0.0, 0.0]])
    hit = kit_model_check(text, names, "link_6", payload, folded, zero, zero, assets)
    assert hit["contacts"].startswith("on")
    # links driven into each other: the contact forces load J2/J3 far beyond gravity alone
    assert max(hit["fraction"]) > 2 * max(free["fraction"]) + 0.5


@slow
def test_rosie_1400_servos_reach_the_first_benchmark_point(kit_factory):
    """On main the 1 kg cycle started with link_2 inside link_4 and the kit's servos stalled
    19.6 deg short of its first point (issue 12); now they hold it, touching nothing."""
    import csv

    kit = kit_factory("rosie_1400").kit_dir
    doc = json.loads((kit / "robot.json").read_text())
    model = mujoco.MjModel.from_xml_path(str(kit / doc["files"]["mjcf"]))
    data = mujoco.MjData(model)
    with (kit / doc["benchmarks"]["trajectory_files"]["cycle_1kg"]["csv"]).open() as handle:
        rows = list(csv.reader(handle))
    q0 = np.array([float(v) for v in rows[1][1:7]])
    data.ctrl[:] = q0
    for _ in range(1500):  # 3 s at 2 ms
        mujoco.mj_step(model, data)
    assert np.degrees(np.abs(data.qpos[:6] - q0).max()) < 0.5 and data.ncon == 0
