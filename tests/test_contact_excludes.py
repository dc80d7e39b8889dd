"""Contact exclusions the source declares (issue 31): an MJCF `<contact><exclude>` becomes the
spec's `contact_excludes`, and every kit format that can filter a pair gets it (MJCF
`<exclude>`, USD filtered pairs, SRDF `User`, the GPU scene); the kit's checks accept the
pair and the MJCF source proof compares the excludes both ways. The spec refuses a pair of
unknown, identical or jointed links in one line.

The model: a palm with two fingers whose tips meet at home (the source lets them overlap)
and part when either joint turns, so the pair is neither adjacent nor always in contact."""

from __future__ import annotations

import hashlib
import json

import pytest
import yaml

from mjcf_models import listed, spec_of, write
from simkit.check.kit import Kit
from simkit.check.source import check_source
from simkit.errors import SpecError
from simkit.kitio import layout
from simkit.spec.validate import load_spec

LINK = '<inertial pos="0 0 0.03" mass="0.05" diaginertia="2e-5 2e-5 5e-6"/>'
HAND = f"""<mujoco model="hand">
  <compiler angle="radian"/>
  <worldbody>
    <body name="palm"><inertial pos="0 0 0" mass="0.5" diaginertia="1e-3 1e-3 1e-3"/>
      <geom type="box" size="0.05 0.03 0.02" pos="0.03 0 -0.02"/>
      <body name="thumb" pos="0.06 0 0.01"><joint name="j_thumb" axis="0 1 0" range="-0.6 0.6"/>
        {LINK}<geom type="capsule" fromto="0 0 0 -0.03 0 0.05" size="0.008"/></body>
      <body name="finger" pos="0 0 0.01"><joint name="j_finger" axis="0 1 0" range="-0.6 0.6"/>
        {LINK}<geom type="capsule" fromto="0 0 0 0.03 0 0.05" size="0.008"/></body>
    </body>{{extra_body}}
  </worldbody>
  <contact><exclude name="tips" body1="thumb" body2="finger"/>{{extra_exclude}}</contact>
</mujoco>
"""


def hand(extra_body: str = "", extra_exclude: str = "") -> str:
    return HAND.replace("{extra_body}", extra_body).replace("{extra_exclude}", extra_exclude)


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hand")
    source = write(folder / "src", hand(), "hand.xml")
    return source, spec_of(source, folder / "out")


def test_the_source_excludes_become_the_spec_s(imported):
    _, spec = imported
    assert spec["contact_excludes"] == [["finger", "thumb"]]
    assert not [w for w in listed(spec) if w.startswith("contact_excludes.")]
    assert spec["poses"]["home"] == [0.0, 0.0]  # the overlap is the source's: home kept


def test_every_format_gets_the_pair_and_the_kit_passes(imported, tmp_path):
    from pxr import Usd, UsdPhysics

    from simkit.pipeline import build

    source, _ = imported
    result = build(str(source.parent.parent / "out" / "hand.yaml"), tmp_path / "kits")
    failed = [f.line() for f in result.findings if not f.ok]
    assert not failed
    kit = result.kit_dir
    assert '<exclude body1="finger" body2="thumb" />' in (kit / "mjcf/hand.xml").read_text()
    srdf = (kit / "srdf/hand.srdf").read_text()
    assert '<disable_collisions link1="finger" link2="thumb" reason="User" />' in srdf
    doc = json.loads((kit / "robot.json").read_text())
    assert doc["collision_pairs"]["declared"] == [["finger", "thumb"]]
    stage = Usd.Stage.Open(str(kit / layout.usd_payload("hand", "physics.usda")))
    filtered = {
        (prim.GetName(), target.name)
        for prim in stage.TraverseAll()
        if prim.HasAPI(UsdPhysics.FilteredPairsAPI)
        for target in UsdPhysics.FilteredPairsAPI(prim).GetFilteredPairsRel().GetTargets()
    }
    assert ("thumb", "finger") in filtered
    names = {f.check for f in result.findings}
    assert {"mjcf.excludes", "source.excludes"} <= names


def test_a_pair_with_a_body_outside_the_robot_is_listed(tmp_path):
    table = '\n    <body name="table" pos="0 0 -0.5"><geom type="box" size="0.3 0.3 0.02"/></body>'
    text = hand(table, '<exclude name="rest" body1="table" body2="palm"/>')
    spec = spec_of(write(tmp_path / "src", text, "hand.xml"), tmp_path / "out")
    assert spec["contact_excludes"] == [["finger", "thumb"]]
    assert "no link" in listed(spec)["contact_excludes.rest"]


@pytest.mark.parametrize(
    ("pairs", "why"),
    [
        ([["finger", "pinky"]], "unknown link 'pinky'"),
        ([["finger", "finger"]], "excluded from itself"),
        ([["palm", "thumb"]], "joined by a joint"),
        ([["finger", "thumb"], ["thumb", "finger"]], "listed twice"),
    ],
)
def test_the_spec_refuses_a_bad_pair_in_one_line(imported, tmp_path, pairs, why):
    source, spec = imported
    out = source.parent.parent / "out"
    changed = tmp_path / "hand.yaml"
    changed.write_text(yaml.safe_dump({**spec, "contact_excludes": pairs}, sort_keys=False))
    for item in out.iterdir():  # the meshes and kept source beside the spec
        if item.name != "hand.yaml":
            (tmp_path / item.name).symlink_to(item)
    with pytest.raises(SpecError) as err:
        load_spec(changed)
    text = str(err.value)
    assert "contact_excludes[" in text and why in text and "\n" not in text


def _kit(tmp_path, kit_text: str, declared=()) -> Kit:
    """A kit folder holding what the source check reads: robot.json and its MJCF."""
    source = write(tmp_path / "src", hand(), "hand.xml")
    folder = tmp_path / "kit"
    write(folder, kit_text, "hand.xml")
    doc = {
        "files": {"mjcf": "hand.xml"},
        "source": {"file": "hand.xml", "sha256": hashlib.sha256(source.read_bytes()).hexdigest()},
        "collision_pairs": {"declared": [list(p) for p in declared]},
    }
    (folder / "robot.json").write_text(json.dumps(doc))
    return Kit(folder, source)


def _excludes(kit: Kit) -> list[str]:
    return [f.line() for f in check_source(kit) if f.check == "source.excludes" and not f.ok]


def test_the_source_proof_compares_the_excludes_both_ways(tmp_path):
    assert _excludes(_kit(tmp_path / "same", hand(), [("finger", "thumb")])) == []
    dropped = hand().replace('<exclude name="tips" body1="thumb" body2="finger"/>', "")
    lines = _excludes(_kit(tmp_path / "dropped", dropped))
    assert len(lines) == 1 and "'finger' and 'thumb'" in lines[0] and "not the kit" in lines[0]
    more = hand(extra_exclude='<exclude body1="palm" body2="finger"/>')
    extra = _excludes(_kit(tmp_path / "more", more, [("finger", "thumb"), ("finger", "palm")]))
    assert len(extra) == 1 and "'finger' and 'palm'" in extra[0] and "declared" in extra[0]
