"""SRDF: planning groups, named poses, virtual joint, end effector, disabled collision pairs.

The "Never" pairs are verified independently of MuJoCo: PyBullet's own collision detection
on the written URDF, at configurations regenerated from robot.json's recorded seed.
"""

from __future__ import annotations

import itertools
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from simkit.emit import srdf
from simkit.errors import SpecError
from simkit.model.resolve import resolve
from simkit.pipeline import find_spec
from simkit.spec.validate import load_spec


def _srdf(kit: Path) -> ET.Element:
    return ET.parse(kit / "srdf" / "rosie_1000.srdf").getroot()


def _disabled(root: ET.Element) -> dict[tuple[str, str], str]:
    return {
        tuple(sorted((d.get("link1"), d.get("link2")))): d.get("reason")
        for d in root.iter("disable_collisions")
    }


def test_groups_states_virtual_joint_end_effector(rosie_1000):
    root = _srdf(rosie_1000.kit_dir)
    doc = json.loads((rosie_1000.kit_dir / "robot.json").read_text())
    chain = root.find("group[@name='manipulator']/chain")
    assert (chain.get("base_link"), chain.get("tip_link")) == ("base_link", "tool0")
    states = {s.get("name"): s for s in root.iter("group_state")}
    assert set(states) == {"home", "work", "stretched"}
    names = [j["name"] for j in doc["joints"]]
    for name, state in states.items():
        values = {j.get("name"): float(j.get("value")) for j in state.iter("joint")}
        assert list(values) == names
        assert np.allclose(list(values.values()), doc["poses"][name], atol=1e-9)
    assert math.degrees(
        float(states["work"].find("joint[@name='J2']").get("value"))
    ) == pytest.approx(30)
    vj = root.find("virtual_joint")
    assert (vj.get("type"), vj.get("parent_frame"), vj.get("child_link")) == (
        "fixed",
        "world",
        "base_footprint",
    )
    eef = root.find("end_effector")
    assert eef.get("parent_link") == "tool0" and eef.get("parent_group") == "manipulator"
    assert root.find(f"group[@name='{eef.get('group')}']/link").get("name") == "tool0"


def test_every_adjacent_pair_disabled(rosie_1000):
    urdf = ET.parse(rosie_1000.kit_dir / "urdf" / "rosie_1000.urdf").getroot()
    solid = {link.get("name") for link in urdf.iter("link") if link.find("collision") is not None}
    adjacent = {
        tuple(sorted((j.find("parent").get("link"), j.find("child").get("link"))))
        for j in urdf.iter("joint")
    }
    adjacent = {pair for pair in adjacent if set(pair) <= solid}
    assert len(adjacent) == 6
    disabled = _disabled(_srdf(rosie_1000.kit_dir))
    for pair in adjacent:
        assert disabled.get(pair) == "Adjacent", pair
    assert set(disabled.values()) <= {"Adjacent", "Never"}
    assert {p for p, r in disabled.items() if r == "Adjacent"} == adjacent
    assert all(set(pair) <= solid for pair in disabled)


def test_never_pairs_never_touch_in_pybullet(rosie_1000):
    pybullet = pytest.importorskip("pybullet")
    kit = rosie_1000.kit_dir
    doc = json.loads((kit / "robot.json").read_text())
    block = doc["collision_pairs"]
    assert block["samples"] >= 10_000 and block["seed"] == doc["provenance"]["seeds"]["spec"]
    disabled = _disabled(_srdf(kit))
    never = [tuple(p) for p in block["never"]]
    assert never and {p for p, r in disabled.items() if r == "Never"} == set(never)
    # Regenerate the sampled configurations from robot.json alone.
    joints = {j["name"]: j for j in doc["joints"]}
    limits = np.array([(joints[n]["lower"], joints[n]["upper"]) for n in block["joints"]])
    unit = np.random.default_rng(block["seed"]).random((block["samples"], len(limits)))
    q = limits[:, 0] + unit * (limits[:, 1] - limits[:, 0])
    client = pybullet.connect(pybullet.DIRECT)
    try:
        robot = pybullet.loadURDF(
            str(kit / "urdf" / "rosie_1000.urdf"), useFixedBase=True, physicsClientId=client
        )
        info = [
            pybullet.getJointInfo(robot, i, physicsClientId=client)
            for i in range(pybullet.getNumJoints(robot, physicsClientId=client))
        ]
        link = {i[12].decode(): i[0] for i in info}
        joint = {i[1].decode(): i[0] for i in info}

        def touching(row, a, b) -> bool:
            for name, value in zip(block["joints"], row, strict=True):
                pybullet.resetJointState(robot, joint[name], value, physicsClientId=client)
            return bool(
                pybullet.getClosestPoints(
                    robot, robot, 0.0, link[a], link[b], physicsClientId=client
                )
            )

        # The checker sees contacts: each pair the sampler found touching touches here too.
        first = {tuple(k.split()): i for k, i in block["first_contact"].items()}
        assert first
        for (a, b), index in first.items():
            assert touching(q[index], a, b), (a, b, index)
        # And the "Never" pairs never touch on a subsample (every 4th configuration).
        for index in range(0, len(q), 4):
            for a, b in never:
                assert not touching(q[index], a, b), (a, b, index)
    finally:
        pybullet.disconnect(client)
    # Every pair is accounted for: adjacent, never, or seen touching.
    solid = sorted({n for pair in disabled for n in pair} | {n for p in first for n in p})
    for pair in itertools.combinations(solid, 2):
        assert (pair in disabled) != (pair in first), pair


def _resolved(tmp_path: Path, extra: str):
    text = find_spec("rosie_1000")[0].read_text() + extra
    path = tmp_path / "groups.yaml"
    path.write_text(text)
    spec, doc = load_spec(path)
    return resolve(spec, doc.text.encode(), path.name)


def test_spec_declared_planning_groups(tmp_path):
    robot = _resolved(
        tmp_path,
        "planning_groups:\n"
        "  - {name: arm, base: base_link, tip: link_3}\n"
        "  - {name: wrist, base: link_3, tip: tool0}\n",
    )
    root = ET.fromstring(srdf.emit(robot)["srdf/rosie_1000.srdf"])
    chains = {
        g.get("name"): (g.find("chain").get("base_link"), g.find("chain").get("tip_link"))
        for g in root.iter("group")
        if g.find("chain") is not None
    }
    assert chains == {"arm": ("base_link", "link_3"), "wrist": ("link_3", "tool0")}
    states = {
        (s.get("group"), s.get("name")): [j.get("name") for j in s.iter("joint")]
        for s in root.iter("group_state")
    }
    assert states[("arm", "home")] == ["J1", "J2", "J3"]
    assert states[("wrist", "stretched")] == ["J4", "J5", "J6"]
    assert root.find("end_effector").get("parent_group") == "wrist"


def test_planning_group_tip_must_be_below_base(tmp_path):
    with pytest.raises(SpecError) as info:
        _resolved(tmp_path, "planning_groups:\n  - {name: arm, base: link_3, tip: link_1}\n")
    assert info.value.field == "planning_groups[0].tip" and info.value.line is not None


def test_never_pairs_never_touch_in_fresh_configurations(rosie_1000):
    """The "Never" pairs on configurations the sampler never saw (another seed, 20,000 of
    them within the limits), on the MJCF's collision geometry: MuJoCo tests only those
    pairs (explicit <pair>s, margin 0). A pair the sampler saw touch is the control that
    the detection works."""
    mujoco = pytest.importorskip("mujoco")
    kit = rosie_1000.kit_dir
    doc = json.loads((kit / "robot.json").read_text())
    never = [tuple(p) for p in doc["collision_pairs"]["never"]]
    first = doc["collision_pairs"]["first_contact"]
    control = tuple(min(first, key=first.get).split())  # the pair the sampler saw touch first
    assert control not in never and never
    path = kit / "mjcf" / "rosie_1000.xml"
    root = ET.parse(path).getroot()
    compiler = root.find("compiler")
    compiler.set("meshdir", str((path.parent / compiler.get("meshdir")).resolve()))
    geoms: dict[str, list[ET.Element]] = {}
    for body in root.iter("body"):
        for geom in body.findall("geom"):
            geom.set("contype", "0")  # only the explicit pairs below collide
            geom.set("conaffinity", "0")
            if geom.get("class") == "collision":
                geoms.setdefault(body.get("name"), []).append(geom)
    contact = root.find("contact")
    if contact is None:
        contact = ET.SubElement(root, "contact")
    for a, b in [*never, control]:
        for ga, gb in itertools.product(geoms[a], geoms[b]):
            ET.SubElement(contact, "pair", geom1=ga.get("name"), geom2=gb.get("name"), margin="0")
    model = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    data = mujoco.MjData(model)
    joints = doc["joints"]
    adr = [model.jnt_qposadr[model.joint(j["name"]).id] for j in joints]
    lower = np.array([j["lower"] for j in joints])
    upper = np.array([j["upper"] for j in joints])
    unit = np.random.default_rng(doc["collision_pairs"]["seed"] + 1).random((20_000, len(adr)))
    touched: dict[tuple[str, str], int] = {}
    for row in lower + unit * (upper - lower):
        data.qpos[adr] = row
        mujoco.mj_kinematics(model, data)
        mujoco.mj_collision(model, data)
        for g1, g2 in data.contact.geom[: data.ncon]:
            names = sorted(model.body(model.geom_bodyid[g]).name for g in (g1, g2))
            touched[tuple(names)] = touched.get(tuple(names), 0) + 1
    assert touched.get(control, 0) > 0  # the detection sees contacts
    assert not {pair: n for pair, n in touched.items() if pair in never}
