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
    assert on_disk == {"index.json", kit["zip"]["path"]} | {f["url"] for f in kit["files"]}


def test_publish_refuses_a_folder_that_is_not_a_publication(tmp_path):
    (tmp_path / "notes.txt").write_text("keep me")
    with pytest.raises(SimkitError, match="not an earlier publication"):
        publish(tmp_path, ["rosie_1000"])
    assert (tmp_path / "notes.txt").read_text() == "keep me"
