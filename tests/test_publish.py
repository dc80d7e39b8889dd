"""`simkit publish`: zips, per-file folders and an index.json whose sizes and hashes are true."""

from __future__ import annotations

import hashlib
import json
import zipfile

import pytest

from simkit.errors import SimkitError
from simkit.publish import publish


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def test_index_lists_every_file_with_true_size_and_sha256(rosie_1000_published):
    site, index = rosie_1000_published
    assert json.loads((site / "index.json").read_text()) == index
    (kit,) = index["kits"]
    assert kit["name"] == "rosie_1000" and kit["folder"] == "1000/"  # the page's /assets/sim/1000/
    zip_data = (site / kit["zip"]["path"]).read_bytes()
    assert kit["zip"]["path"] == "rosie-1000-sim-kit.zip"
    assert (kit["zip"]["size"], kit["zip"]["sha256"]) == (len(zip_data), _sha(zip_data))
    with zipfile.ZipFile(site / kit["zip"]["path"]) as archive:
        in_zip = {i.filename: archive.read(i) for i in archive.infolist()}
    assert sorted(in_zip) == [f["path"] for f in kit["files"]]
    for entry in kit["files"]:
        data = in_zip[entry["path"]]
        assert (entry["size"], entry["sha256"]) == (len(data), _sha(data)), entry["path"]
        served = (site / entry["url"]).read_bytes()
        assert served == data, entry["url"]
    on_disk = {p.relative_to(site).as_posix() for p in site.rglob("*") if p.is_file()}
    pages = {"index.html", "site.css", kit["page"]}
    viewer = {p for p in on_disk if p.startswith("viewer/")}
    assert "viewer/vendor/mujoco/mujoco.wasm" in viewer and "viewer/viewer.js" in viewer
    assert on_disk - viewer == {"index.json", kit["zip"]["path"]} | pages | {
        f["url"] for f in kit["files"]
    }


def test_index_format_2_carries_the_registry_facts_and_keeps_format_1s(rosie_1000_published):
    """Issue 40: licence, category, DoF, entry points and the checks, as Menagerie's registry;
    every field of format 1 is still there."""
    site, index = rosie_1000_published
    assert index["format"] == 2
    (kit,) = index["kits"]
    assert {"name", "title", "folder", "top_folder", "zip", "files"} <= set(kit)
    doc = json.loads((site / kit["folder"] / "robot.json").read_text())
    assert kit["category"] == "arm" and kit["dof"] == 6
    assert kit["licence"] == "LicenseRef-rosie_1000_description"
    assert kit["mass"] == doc["mass"]["model"]
    assert kit["entry_points"] == {
        "mjcf": "mjcf/rosie_1000.xml",
        "gpu_scene": "mjcf/rosie_1000_mjx.xml",
        "urdf": "urdf/rosie_1000.urdf",
        "usd": "usd/rosie_1000.usda",
        "sdf": "sdf/rosie_1000.sdf",
        "glb": "glb/rosie_1000.glb",
    }
    for path in [*kit["entry_points"].values(), kit["thumbnail"]]:
        assert (site / kit["folder"] / path).is_file(), path
    assert kit["checks"]["mjcf"]["tools"] == ["MuJoCo"]
    assert all(g["passed"] == g["total"] > 0 for g in kit["checks"].values())
    page = (site / kit["page"]).read_text()
    assert kit["zip"]["sha256"] in page and "Quickstart" in page


def test_publish_refuses_a_folder_that_is_not_a_publication(tmp_path):
    (tmp_path / "notes.txt").write_text("keep me")
    with pytest.raises(SimkitError, match="not an earlier publication"):
        publish(tmp_path, ["rosie_1000"])
    assert (tmp_path / "notes.txt").read_text() == "keep me"


def _snapshot(site):
    seen = {}
    for path in [site, *sorted(site.rglob("*"))]:
        st = path.lstat()
        data = path.read_bytes() if path.is_file() else None
        seen[path.relative_to(site).as_posix()] = (data, st.st_ino, st.st_mtime_ns)
    return seen


@pytest.mark.slow
def test_republishing_rewrites_only_what_changed(tmp_path):
    """The site folder (rsynced to the server) follows the build folder's rules: publishing
    the same kits again changes no byte, name or mtime; after a change, the files whose bytes
    did not change keep their inode and mtime, and nothing hidden is left beside the site."""
    from pathlib import Path

    spec = tmp_path / "planar_2r.yaml"
    source = Path(__file__).resolve().parent / "specs" / "planar_2r.yaml"
    spec.write_text(source.read_text())
    site = tmp_path / "out" / "sim"
    publish(site, [str(spec)])
    before = _snapshot(site)
    publish(site, [str(spec)])
    assert _snapshot(site) == before
    spec.write_text(source.read_text().replace("title: Planar 2R", "title: Planar 2R arm"))
    publish(site, [str(spec)])
    after = _snapshot(site)
    changed = sorted(p for p in before if p in after and after[p][0] != before[p][0])
    assert "index.json" in changed and any(p.endswith("robot.json") for p in changed)
    kept = [p for p in before if before[p][0] is not None and p not in changed]
    assert any(p.endswith(".stl") for p in kept)
    assert all(after[p][1:] == before[p][1:] for p in kept)
    assert sorted(p.name for p in site.parent.iterdir()) == ["sim"]
