"""`simkit diff` and `simkit check` on hostile kits (issue 13): malformed robot.json,
encrypted or oversized zip entries, symlinks and paths leaving the kit. One line, no
traceback, no unbounded memory."""

from __future__ import annotations

import json
import os
import re
import zipfile
from pathlib import Path

import pytest
from click.testing import CliRunner

from simkit.cli import main
from simkit.diff import load_kit
from simkit.errors import SimkitError
from simkit.kitio import kitread

DOC = {"name": "toy", "joints": [], "fixed_joints": [], "links": [], "frames": {}, "files": {}}


def _kit(root: Path, doc: object = DOC) -> Path:
    root.mkdir(parents=True)
    (root / "robot.json").write_text(json.dumps(doc))
    return root


def _zip(path: Path, entries: dict[str, bytes], encrypt: set[str] = frozenset()) -> Path:
    with zipfile.ZipFile(path, "w") as archive:
        for name, data in entries.items():
            archive.writestr(zipfile.ZipInfo(name), data)
    data = bytearray(path.read_bytes())  # zipfile cannot encrypt: set the flag bit by hand
    for signature, flag_at, length_at, name_at in (
        (b"PK\x03\x04", 6, 26, 30),
        (b"PK\x01\x02", 8, 28, 46),
    ):
        start = data.find(signature)
        while start >= 0:
            size = int.from_bytes(data[start + length_at : start + length_at + 2], "little")
            if data[start + name_at : start + name_at + size].decode() in encrypt:
                data[start + flag_at] |= 0x1
            start = data.find(signature, start + 4)
    path.write_bytes(bytes(data))
    return path


BAD_DOCS = [
    ([1, 2], "must be a JSON object, not a list"),
    ({**DOC, "joints": {"a": 1}}, "'joints' must be a JSON list"),
    ({**DOC, "name": 3}, "'name' must be a JSON str"),
    ({**DOC, "links": [1]}, "'links[0]' must be an object"),
    ({**DOC, "files": {"urdf": "../../etc/passwd"}}, "'files.urdf' must be a path inside"),
    ({k: v for k, v in DOC.items() if k != "name"}, "'name' is missing"),
]


@pytest.mark.parametrize("doc,message", BAD_DOCS, ids=[m for _, m in BAD_DOCS])
def test_malformed_robot_json_is_one_line(tmp_path, doc, message):
    bad, good = _kit(tmp_path / "bad", doc), _kit(tmp_path / "good")
    with pytest.raises(SimkitError, match=re.escape(message)):
        load_kit(bad)
    runner = CliRunner()
    for args in (["diff", str(good), str(bad)], ["check", str(bad)]):
        result = runner.invoke(main, args)
        assert result.exit_code == 2, result.output
        lines = result.output.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("simkit: error: "), result.output
        assert message in lines[0]


def test_hostile_zips_are_refused(tmp_path, monkeypatch):
    doc = json.dumps(DOC).encode()
    cases = {
        "encrypted": ({"k/robot.json": doc, "k/a.txt": b"x"}, {"k/a.txt"}, "encrypted"),
        "dotdot": ({"k/robot.json": doc, "k/../../evil": b"x"}, set(), "leaves the kit"),
        "absolute": ({"robot.json": doc, "/etc/evil": b"x"}, set(), "leaves the kit"),
        "big": ({"k/robot.json": doc, "k/big.bin": b"\0" * 4096}, set(), "over"),
    }
    monkeypatch.setattr(kitread, "MAX_ENTRY", 1024)
    for name, (entries, encrypt, message) in cases.items():
        path = _zip(tmp_path / f"{name}.zip", entries, encrypt)
        with pytest.raises(SimkitError, match=message):
            load_kit(path)


def test_oversized_entry_is_capped_while_reading(tmp_path, monkeypatch):
    """The cap holds even when the header lies about the size (read with a limit)."""
    monkeypatch.setattr(kitread, "MAX_ENTRY", 1 << 16)
    path = _zip(tmp_path / "k.zip", {"robot.json": json.dumps(DOC).encode()})
    with zipfile.ZipFile(path, "a", compression=zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("bomb.bin", b"\0" * (1 << 22))  # 4 MiB that deflates to ~4 kB
    assert path.stat().st_size < 64 << 10
    with pytest.raises(SimkitError, match="over"):
        load_kit(path)


def test_symlinks_in_a_kit_folder_are_refused(tmp_path):
    kit = _kit(tmp_path / "kit")
    (tmp_path / "secret").write_text("outside")
    os.symlink(tmp_path / "secret", kit / "meshes.stl")
    with pytest.raises(SimkitError, match="symlink"):
        load_kit(kit)
    result = CliRunner().invoke(main, ["check", str(kit)])
    lines = result.output.strip().splitlines()
    assert result.exit_code == 2 and len(lines) == 1 and "symlink" in lines[0], result.output


def test_inside():
    assert kitread.inside("a/b.txt") and kitread.inside("a/../b")
    for rel in ("", "/a", "../a", "a/../../b", "..", "C:/x", "a\\..\\b", "."):
        assert not kitread.inside(rel), rel
