"""The USD source proof (check/source/usd/, issue 39) on a kit URDF written from the
imported spec: it passes on the robot the stage describes, and fails, naming the link or
joint, on a mass, a limit, an effort or a joint origin that differs."""

from __future__ import annotations

import json
import math

import pytest
import yaml
from tests.usd_stages import arm

from simkit.check.kit import Kit
from simkit.check.source import usd as source_usd
from simkit.importer import import_robot

pytest.importorskip("pxr")


def _urdf(spec: dict) -> str:
    """The spec's links and joints as URDF text (what the build's URDF carries)."""
    out = ['<robot name="arm">']
    for link in spec["links"]:
        i = link["inertia"]
        out += [
            f'<link name="{link["name"]}"><inertial><origin xyz="{_v(link["com"])}"/>',
            f'<mass value="{link["mass"]!r}"/><inertia ixx="{i["ixx"]!r}" ixy="{i.get("ixy", 0)!r}"'
            f' ixz="{i.get("ixz", 0)!r}" iyy="{i["iyy"]!r}" iyz="{i.get("iyz", 0)!r}"'
            f' izz="{i["izz"]!r}"/></inertial></link>',
        ]
    out += ['<link name="world"/>', *(f'<link name="{n}"/>' for n in _added(spec))]
    for j in spec["joints"]:
        limit = ""
        if "lower" in j:
            limit = (
                f'<limit lower="{j["lower"]!r}" upper="{j["upper"]!r}"'
                f' effort="{j.get("effort_peak", 1)!r}" velocity="1"/>'
            )
        out.append(
            f'<joint name="{j["name"]}" type="{j["type"]}"><parent link="{j["parent"]}"/>'
            f'<child link="{j["child"]}"/><origin xyz="{_v(j.get("xyz", [0, 0, 0]))}"'
            f' rpy="{_v(j.get("rpy", [0, 0, 0]))}"/><axis xyz="{_v(j.get("axis", [1, 0, 0]))}"/>'
            f"{limit}</joint>"
        )
    return "\n".join([*out, "</robot>"])


def _added(spec: dict) -> list[str]:
    """Links the joints name that the spec's links do not hold (massless chain links)."""
    named = {link["name"] for link in spec["links"]} | {"world"}
    return sorted({j["child"] for j in spec["joints"]} - named)


def _v(values) -> str:
    return " ".join(repr(float(v)) for v in values)


@pytest.fixture(scope="module", params=["plain", "chain", "two_roots"])
def imported(tmp_path_factory, request):
    """The arm imported; with two joints between one pair of bodies (a chain); with two
    articulations bolted to the robot's prim."""
    folder = tmp_path_factory.mktemp("usd_source")
    options = {} if request.param == "plain" else {request.param: True}
    done = import_robot(arm(folder / "arm.usda", **options), folder / "out")
    return done.spec_path, yaml.safe_load(done.spec_path.read_text())


def _findings(tmp_path, imported, change=None) -> list:
    spec_path, spec = imported
    spec = json.loads(json.dumps(spec))
    if change:
        change(spec)
    kit = tmp_path / "kit"
    kit.mkdir()
    (kit / "arm.urdf").write_text(_urdf(spec))
    doc = {"name": "arm", "files": {"urdf": "arm.urdf"}, "source": spec["source"]}
    doc["source_differences"] = spec.get("source_differences", [])
    (kit / "robot.json").write_text(json.dumps(doc))
    given = spec_path.parent / spec["source"]["file"]
    return source_usd.compare(Kit(kit, given), given)


def _by_name(items: list[dict]) -> dict:
    return {item["name"]: item for item in items}


def test_passes(tmp_path, imported) -> None:
    found = _findings(tmp_path, imported)
    assert all(f.ok for f in found), [str(f) for f in found if not f.ok]
    assert {f.check for f in found} >= {"source.joints", "source.links", "source.fk"}


def test_mass_differs(tmp_path, imported) -> None:
    def heavier(spec):
        _by_name(spec["links"])["upper"]["mass"] *= 1.001

    failed = [f.detail for f in _findings(tmp_path, imported, heavier) if not f.ok]
    assert any("'upper': mass" in d for d in failed)


def test_limit_differs(tmp_path, imported) -> None:
    def wider(spec):
        _by_name(spec["joints"])["shoulder"]["upper"] = math.radians(50)

    failed = [f.detail for f in _findings(tmp_path, imported, wider) if not f.ok]
    assert any("'shoulder': upper" in d for d in failed)


def test_effort_differs(tmp_path, imported) -> None:
    """The shoulder's drive maxForce (20 N m, no `simkit:effortLimit`) is its effort."""

    def stronger(spec):
        _by_name(spec["joints"])["shoulder"]["effort_peak"] = 20.1

    failed = [f.detail for f in _findings(tmp_path, imported, stronger) if not f.ok]
    assert any("'shoulder': effort 20 in the USD, 20.1 in the kit" in d for d in failed)


def test_origin_differs(tmp_path, imported) -> None:
    def moved(spec):
        _by_name(spec["joints"])["slide"]["xyz"] = [0.0, 0.0, 0.5001]

    failed = [f for f in _findings(tmp_path, imported, moved) if not f.ok]
    assert any(f.check == "source.fk" and "'slider'" in f.detail for f in failed)
