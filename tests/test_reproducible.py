"""Two builds of the same spec give byte-identical files and zips."""

from __future__ import annotations

import difflib
import zipfile

from simkit.kitio import layout
from simkit.kitio.archive import FIXED_TIME


def _tree(root):
    return {
        p.relative_to(root).as_posix(): p.read_bytes()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def test_two_builds_are_byte_identical(rosie_1000, rosie_1000_published):
    site, index = rosie_1000_published
    kit = index["kits"][0]
    first = _tree(rosie_1000.kit_dir)
    second = _tree(site / kit["folder"])
    # the site adds the kit's page beside its files (docs/publish.md); the files are the kit's
    assert b"<html" in second.pop("index.html")
    assert len(first) > 20
    assert sorted(first) == sorted(second)
    different = [path for path in first if first[path] != second[path]]
    detail = ""
    if different and different[0].endswith((".json", ".xml", ".urdf", ".srdf", ".usda", ".md")):
        lines = difflib.unified_diff(
            first[different[0]].decode().splitlines(),
            second[different[0]].decode().splitlines(),
            lineterm="",
            n=1,
        )
        detail = "\n".join(list(lines)[:20])
    assert not different, f"{different}\n{detail}"
    zip_a = rosie_1000.zip_path.read_bytes()
    zip_b = (site / layout.zip_name("rosie_1000")).read_bytes()
    assert zip_a == zip_b


def test_zip_is_sorted_with_fixed_times_and_modes(rosie_1000):
    with zipfile.ZipFile(rosie_1000.zip_path) as archive:
        infos = archive.infolist()
    names = [i.filename for i in infos]
    assert names == sorted(names)
    assert all(n.startswith("rosie_1000_description/") for n in names)
    assert {i.date_time for i in infos} == {FIXED_TIME}
    assert {i.external_attr >> 16 for i in infos} == {0o100644}
