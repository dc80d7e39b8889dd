"""The source check's reader is no stricter than the importer (issue 32, class 9): where
yourdfpy cannot read the source as written but can once the importer's lenient readings
apply (a `<robot>` without a name), the kit is compared with the source read so, and the
finding says which fix applied; a source no fix makes readable still fails."""

from __future__ import annotations

from simkit.check.source.urdf import _read_leniently, load_urdf
from simkit.importer import import_robot
from urdf_parts import joint, link, write

LINKS = link("base") + link("arm")
JOINT = joint("hinge", "base", "arm")


def test_a_nameless_robot_is_compared_as_the_importer_read_it(tmp_path):
    from simkit.pipeline import build

    urdf = write(tmp_path, "nameless", LINKS, JOINT, robot="")
    done = import_robot(urdf, tmp_path / "out")
    result = build(str(done.spec_path), tmp_path / "kits")  # CheckFailed on any failure
    read = [f for f in result.findings if f.check == "source.read"]
    assert len(read) == 1 and read[0].ok
    assert "the <robot> has no name" in read[0].line() and "cannot read" in read[0].line()
    assert any(f.check == "source.joints" and f.ok for f in result.findings)


def test_a_source_no_fix_makes_readable_is_not_read(tmp_path):
    urdf = tmp_path / "bad.urdf"
    urdf.write_text(f'<robot name="r"><link/>{LINKS}</robot>\n')  # a link without a name
    robot, fixes = _read_leniently(urdf)
    assert robot is None and fixes == []


def test_a_readable_source_needs_no_fix(tmp_path):
    urdf = tmp_path / "ok.urdf"
    urdf.write_text(f'<robot name="r">{LINKS}{JOINT}</robot>\n')
    fixes: list[str] = []
    assert [j.name for j in load_urdf(urdf, fixes).joints] == ["hinge"] and fixes == []
