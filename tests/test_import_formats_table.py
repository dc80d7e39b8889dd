"""One module per format behind one table (issue 39): the importer's `formats.FORMATS` and the
source check's `COMPARE` name the same formats, every format module gives sniff, title,
read and keep, and the format is picked once, by what the file is. Small handwritten files."""

from __future__ import annotations

import ast
from pathlib import Path

from simkit.check import source as source_check
from simkit.importer import formats
from simkit.importer.diagnostics import Report

IMPORTER = Path(formats.__file__).resolve().parents[1]
XACRO = (
    '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
    '<xacro:property name="n" value="base"/><link name="${n}"/></robot>'
)


def test_the_two_tables_name_the_same_formats():
    assert [f.name for f in formats.FORMATS] == ["xacro", "mjcf", "sdf", "usd", "urdf"]
    assert (
        set(formats.BY_NAME)
        == set(source_check.COMPARE)
        == {
            "urdf",
            "xacro",
            "mjcf",
            "sdf",
            "usd",
        }
    )


def test_every_format_module_gives_sniff_read_and_keep():
    for fmt in formats.FORMATS:
        for part in ("sniff", "title", "read", "keep"):
            assert callable(getattr(fmt, part)), f"{fmt.name}.{part}"
        assert all(callable(step) for step in (*fmt.edits, *fmt.after))


def test_the_format_is_picked_by_what_the_file_is(tmp_path):
    names = ("a.urdf", "a.xacro", "a.urdf.xacro", "a.URDF")
    assert [formats.pick(tmp_path / n).format.name for n in names] == [
        "urdf",
        "xacro",
        "xacro",
        "urdf",
    ]
    model = tmp_path / "m.xml"  # an MJCF by its root element, not its name
    model.write_text("<!-- a model -->\n<mujoco model='Two Arm'><worldbody/></mujoco>")
    picked = formats.pick(model)
    assert (picked.format.name, picked.title) == ("mjcf", "Two Arm")
    (tmp_path / "u.xml").write_text("<robot name='r'><link name='a'/></robot>")
    assert formats.pick(tmp_path / "u.xml").format.name == "urdf"
    for name in ("r.usd", "r.usda", "r.USDC"):  # a USD by its suffix
        assert formats.pick(tmp_path / name).format.name == "usd"
    xacro = tmp_path / "r.urdf.xacro"
    xacro.write_text(XACRO)
    doc = formats.load(xacro, (), Report())
    assert doc.format == "xacro"
    assert [e.get("name") for e in doc.root.iter("link")] == ["base"]
    assert doc.kept is not None and doc.kept.root is not doc.root  # kept as read


def test_the_import_reads_the_file_head_once(tmp_path, monkeypatch):
    """The CLI's import picks the format (and the default name) from one read of the head."""
    from simkit.importer import import_robot

    urdf = tmp_path / "r.urdf"
    urdf.write_text('<robot name="r"><link name="a"><inertial><mass value="1"/>'
                    '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
                    "</inertial></link></robot>")  # fmt: skip
    heads = []
    real = formats.head
    monkeypatch.setattr(formats, "head", lambda path: heads.append(path) or real(path))
    import_robot(urdf, tmp_path / "out")
    assert heads == [urdf]


def test_the_source_check_picks_its_comparison_from_robot_json():
    assert source_check.format_of({"source": {"file": "a.source.urdf", "format": "mjcf"}}) == (
        "mjcf"
    )
    # a kit imported before robot.json named the format: its kept file's suffix
    assert source_check.format_of({"source": {"file": "a.source.xml"}}) == "mjcf"
    assert source_check.format_of({"source": {"file": "a.source.urdf"}}) == "urdf"


def test_no_shared_stage_asks_which_format_it_has():
    """translate/, fixups/ and write/ know no format: no import of a format module, no
    isinstance test of a format's source."""
    found = []
    for folder in ("translate", "fixups", "write"):
        for path in sorted((IMPORTER / folder).glob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.ImportFrom) and "formats" in (node.module or ""):
                    found.append(f"{folder}/{path.name}:{node.lineno}")
                if (
                    isinstance(node, ast.Name)
                    and node.id.endswith("Source")
                    and node.id != "Source"
                ):
                    found.append(f"{folder}/{path.name}:{node.lineno}: {node.id}")
    assert found == []
