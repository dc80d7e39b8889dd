"""The importer's structure (issue 31; the formats' table: test_import_formats_table.py): one
diagnostic record whose policy `--strict` promotes, one typed draft every step receives,
and one builder for the scratch MuJoCo models. Small handwritten URDFs."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import pytest
from lxml import etree

from simkit.errors import SpecError
from simkit.importer import import_robot, steps
from simkit.importer.diagnostics import Policy, Report
from simkit.importer.fixups import collide, scratch
from simkit.importer.formats import FORMATS
from simkit.importer.read.source import Source
from simkit.model.resolve import resolve
from simkit.spec.validate import load_spec

FIXUPS = Path(__file__).resolve().parents[1] / "src" / "simkit" / "importer" / "fixups"
ARM = Path(__file__).resolve().parent / "specs" / "urdf" / "pkg_demo" / "urdf" / "arm.urdf"


def _source(tmp_path: Path, report: Report) -> tuple[Source, object]:
    root = etree.fromstring(b'<robot name="r">\n<link name="a"/>\n<link name="b"/>\n</robot>')
    return Source(tmp_path / "r.urdf", root, packages=None, report=report), root


def test_the_policy_makes_an_estimate_a_warning_and_strict_an_error(tmp_path):
    loose = Report()
    source, root = _source(tmp_path, loose)
    loose.estimated(source, root.find("link"), "no mass")
    loose.raise_refused()  # nothing refused without --strict
    assert [(r.line, r.element, r.severity) for r in loose.records] == [(2, "link[a]", "warning")]
    assert loose.lines == ["r.urdf:2: link[a]: estimated: no mass"]

    strict = Report(Policy(strict=True))
    source, root = _source(tmp_path, strict)
    links = root.findall("link")
    strict.estimated(source, links[0], "no mass")
    strict.assumed(source, links[0], "armature")  # no URDF carries one: a note
    strict.estimated(source, links[1], "no inertia")
    assert [r.severity for r in strict.records] == ["error", "note", "error"]
    with pytest.raises(SpecError) as refused:
        strict.raise_refused()
    assert (refused.value.line, refused.value.field, refused.value.more) == (2, "link[a]", 1)
    with pytest.raises(SpecError, match=r"--strict refuses it"):
        source.lenient(links[1], "'xyz' is '0, 0, 1'")


@pytest.mark.parametrize("fmt", FORMATS, ids=lambda f: f.name)
def test_every_step_receives_only_the_draft(fmt):
    found = steps(fmt)
    assert found[0].__name__ == "to_spec"
    assert [list(inspect.signature(step).parameters) for step in found] == [["draft"]] * len(found)


def test_the_scratch_builder_compiles_the_collision_model(tmp_path):
    done = import_robot(ARM, tmp_path / "out")
    spec, doc = load_spec(done.spec_path)
    robot = resolve(spec, doc.text.encode(), done.spec_path.name)
    xml = collide.model_xml(robot, done.spec_path.parent, (), collide.covered_shapes)
    model, data, adr = scratch.compiled(xml, robot.movable_joints)
    assert len(adr) == len(robot.movable_joints) > 0
    assert model.nexclude == len(collide.adjacent(robot)) > 0
    assert model.nbody == len(robot.links) + 1  # the spec's root frame is the world body
    assert data.qpos.shape == (model.nq,)


def test_the_fixups_read_only_the_draft():
    """No fix-up reaches into the source document or another concern's package: the draft
    (and Draft.where, Draft.note) is all they read and report through."""
    reached = []
    for path in sorted(FIXUPS.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Attribute) and node.attr in ("source", "report"):
                reached.append(f"{path.name}:{node.lineno}: .{node.attr}")
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(
                ("simkit.importer.read", "simkit.importer.translate")
            ):
                reached.append(f"{path.name}:{node.lineno}: {node.module}")
    assert len(list(FIXUPS.glob("*.py"))) > 10
    assert reached == []
