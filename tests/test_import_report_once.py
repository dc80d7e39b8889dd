"""A fact about one URDF element is reported once, however many steps read it (a lenient
`xyz` read by the translation and again by a fix-up)."""

from __future__ import annotations

from simkit.importer.diagnostics import Report
from simkit.importer.read.source import Source


def test_the_same_line_is_reported_once(tmp_path):
    from lxml import etree

    root = etree.fromstring(b'<robot name="r">\n<link name="a"/>\n</robot>')
    source = Source(tmp_path / "r.urdf", root, packages=None)
    report = Report()
    link = root.find("link")
    for _ in range(3):
        report.changed(source, link, "'xyz' is '0, 0, 1': read as '0 0 1'")
    report.changed(source, link, "another fact")
    assert report.lines == [
        "r.urdf:2: link[a]: changed: 'xyz' is '0, 0, 1': read as '0 0 1'",
        "r.urdf:2: link[a]: changed: another fact",
    ]
