"""Collision pieces (issue 3): exact convex pieces, greedy merging, CoACD through the cache,
spec primitives, quality figures, and what the URDF and MJCF make of them."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import manifold3d as mf
import numpy as np
import pytest

from simkit.check.geometry import _outside
from simkit.derive import collision
from simkit.derive import per_link as linkwork
from simkit.derive.solids import to_mesh
from simkit.errors import SpecError
from simkit.kitio.cache import Cache
from simkit.kitio.obj import read_mesh
from simkit.kitio.resources import robot_names
from simkit.kitio.stl import from_stl
from simkit.model.robot import Mesh
from simkit.pipeline import model_from_spec

MIX = str(Path(__file__).resolve().parent / "specs" / "collision_mix.yaml")
ROSIES = [name for name in robot_names() if name.startswith("rosie_")]


def _trimesh(mesh: Mesh):
    import trimesh

    return trimesh.Trimesh(mesh.vertices, mesh.faces, process=True)


def test_merge_greedy_takes_the_pair_that_adds_least_volume():
    a = mf.Manifold.cube((1, 1, 1))
    b = mf.Manifold.cube((1, 1, 1)).translate((1, 0, 0))  # touches a: merging adds nothing
    c = mf.Manifold.cube((1, 1, 1)).translate((0, 3, 0))
    merged = collision.merge_greedy([c, a, b], limit=2)
    assert sorted(round(m.volume(), 9) for m in merged) == [1.0, 2.0]


def test_distance_to_surface_matches_a_box():
    box = to_mesh(mf.Manifold.cube((2, 2, 2), center=True))
    rng = np.random.default_rng(0)
    points = rng.uniform(-3, 3, size=(400, 3))
    inside = np.abs(points).max(axis=1) <= 1
    exact = np.where(
        inside,
        1 - np.abs(points).max(axis=1),
        np.linalg.norm(np.maximum(np.abs(points) - 1, 0), axis=1),
    )
    for k in range(0, 400, 40):
        got = collision.max_distance_to_surface(points[k : k + 40], box)
        assert got == pytest.approx(exact[k : k + 40].max(), abs=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("name", ROSIES)
def test_rosie_links_have_at_most_ten_convex_pieces_covering_the_visual(name):
    robot = model_from_spec(name)
    for link in robot.links:
        assert 1 <= len(link.collision) <= 10, link.name
        assert all(_trimesh(p).is_convex for p in link.collision), link.name
        depth = np.min(
            [_outside(link.solid.vertices, p.vertices, p.faces) for p in link.collision], axis=0
        )
        assert depth.max() < 1e-9, link.name
        report = link.collision_report
        assert report["method"] == "convex" and report["pieces"] == len(link.collision)
        assert report["hull_volume_ratio"] <= 1.05
        assert report["coverage"] >= 0.9999
        assert report["visual_to_collision_max_m"] <= 0.002


def test_rosie_1000_kit_writes_the_pieces_and_their_quality(rosie_1000):
    kit = rosie_1000.kit_dir
    doc = json.loads((kit / "robot.json").read_text())
    reports = {g["name"]: g["collision"] for g in doc["geometry"]["links"]}
    assert doc["geometry"]["collision"]["coacd_parameters"]["threshold"] == 0.1
    for link in doc["links"]:
        paths = link["mesh"]["collision"]
        assert paths and reports[link["name"]]["pieces"] == len(paths)
        pieces = [read_mesh(p, (kit / p).read_bytes()) for p in paths]
        assert all(_trimesh(p).is_convex for p in pieces), link["name"]
        visual = from_stl((kit / link["mesh"]["visual"]).read_bytes()).vertices
        depth = np.min([_outside(visual, p.vertices, p.faces) for p in pieces], axis=0)
        assert depth.max() < 1e-6, link["name"]


def test_convex_needs_a_convex_union():
    from simkit.model.resolve import resolve
    from simkit.spec.validate import load_spec

    spec, doc = load_spec(Path(MIX), display=MIX)
    hub = resolve(spec, doc.text.encode(), MIX).link("hub")
    assert collision.method_of(hub) == "coacd"
    with pytest.raises(SpecError, match="convex"):
        collision.method_of(replace(hub, collision_method="convex"))


def test_convex_on_a_subtracted_solid_is_a_spec_error(tmp_path):
    from simkit.spec.validate import load_spec

    text = (
        Path(MIX).read_text().replace("  - name: hub\n", "  - name: hub\n    collision: convex\n")
    )
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(SpecError) as err:
        load_spec(path, display="bad.yaml")
    assert err.value.line is not None and "collision" in err.value.field
    assert "convex primitives" in err.value.message


def _pieces(robot) -> dict[str, list[bytes]]:
    return {
        link.name: [p.vertices.tobytes() + p.faces.tobytes() for p in link.collision]
        for link in robot.links
    }


@pytest.mark.slow
def test_coacd_cached_warm_runs_none_and_corrupt_entries_are_repaired(tmp_path):
    cache = Cache.at(tmp_path / "cache")
    start = collision.COACD_RUNS
    cold = model_from_spec(MIX, cache=cache, jobs=2)  # two CoACD links: the process pool
    assert collision.COACD_RUNS - start == 2
    reports = {link.name: link.collision_report for link in cold.links}
    assert {n: r["method"] for n, r in reports.items()} == {
        "base_link": "convex",
        "bracket": "coacd",
        "hub": "coacd",
        "finger": "primitives",
    }
    assert reports["base_link"]["pieces"] == 10  # 13 primitives merged greedily
    for link in cold.links:
        if link.name != "finger":
            assert 1 <= len(link.collision) <= 10
            assert all(_trimesh(p).is_convex for p in link.collision), link.name
            assert link.collision_report["coverage"] > 0.999
    assert cold.link("finger").collision == ()
    assert cold.products.seeds["coacd"] == cold.seed

    start = collision.COACD_RUNS
    warm = model_from_spec(MIX, cache=Cache.at(tmp_path / "cache"), jobs=2)
    assert collision.COACD_RUNS - start == 0
    assert _pieces(warm) == _pieces(cold)
    assert [link.collision_report for link in warm.links] == list(reports.values())

    keys = {link.name: linkwork._collision_key(link, cold.seed) for link in cold.links}
    base = cache.path(linkwork.COLLISION_STEP, keys["base_link"])
    data = bytearray(base.read_bytes())
    data[len(data) // 2] ^= 0xFF  # corrupt an entry of an exact-pieces link
    base.write_bytes(bytes(data))
    cache.path(linkwork.COLLISION_STEP, keys["bracket"]).unlink()  # delete a CoACD entry
    again_cache = Cache.at(tmp_path / "cache")
    start = collision.COACD_RUNS
    repaired = model_from_spec(MIX, cache=again_cache, jobs=1)
    assert collision.COACD_RUNS - start == 1  # the bracket only
    assert again_cache.stats.repaired == {"collision": 1}
    assert _pieces(repaired) == _pieces(cold)  # seeded CoACD: the same pieces again
    for name in ("base_link", "bracket"):
        assert Cache.at(tmp_path / "cache").get(linkwork.COLLISION_STEP, keys[name]) is not None


def test_outside_depth_by_cells_is_every_plane_at_once():
    """The grid culling keeps, for each point, the plane that gives its maximum."""
    from simkit.model import hull as hull_module

    rng = np.random.default_rng(3)
    hull = to_mesh(mf.Manifold.hull_points(rng.normal(size=(3000, 3))))
    points = rng.uniform(-3.0, 3.0, size=(60_000, 3))
    n, d = collision._halfspaces(hull)
    assert len(points) * len(d) > hull_module.CHUNK  # the cell path, not the small one
    brute = collision.plane_values(points, n, d).max(axis=1)
    assert np.array_equal(collision.outside_depth(points, hull), brute)
