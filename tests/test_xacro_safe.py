"""Safe xacro by default (issue 24): a restricted evaluator, no environment or outside files
unless allowed by name, bounded expansion, and --trust-xacro for trusted files."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from click.testing import CliRunner
from lxml import etree

from simkit.cli import main
from simkit.errors import SpecError
from simkit.importer import formats
from simkit.importer.diagnostics import Report
from simkit.importer.formats import xacro as xacro_safe
from simkit.importer.read.options import ReadOptions

HEAD = '<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'


def _xacro(tmp_path: Path, body: str, name: str = "r.urdf.xacro") -> Path:
    """A xacro in a package (pkg/package.xml, pkg/urdf/NAME) under `tmp_path`."""
    pkg = tmp_path / "pkg"
    (pkg / "urdf").mkdir(parents=True, exist_ok=True)
    (pkg / "package.xml").write_text("<package><name>pkg</name></package>")
    path = pkg / "urdf" / name
    path.write_text(HEAD + body + "\n</robot>\n")
    return path


def _load(path: Path, **options) -> etree._Element:
    return formats.load(path, (), Report(), ReadOptions(**options)).root


def _names(root) -> list[str]:
    return [link.get("name") for link in root.findall("link")]


def test_ordinary_xacro_features_still_expand(tmp_path):
    (tmp_path / "pkg" / "config").mkdir(parents=True)
    (tmp_path / "pkg" / "config" / "dims.yaml").write_text("length: 0.25\nparts: [a, b]\n")
    path = _xacro(
        tmp_path,
        """  <xacro:arg name="side" default="left"/>
  <xacro:property name="dims" value="${xacro.load_yaml('../config/dims.yaml')}"/>
  <xacro:property name="tags" value="${[p.upper() for p in dims['parts']]}"/>
  <xacro:macro name="rod" params="name *origin">
    <link name="${name}"><visual><xacro:insert_block name="origin"/>
      <geometry><box size="0.1 0.1 ${dims['length'] * 2}"/></geometry></visual></link>
  </xacro:macro>
  <xacro:rod name="$(arg side)_${tags[1]}"><origin xyz="0 0 ${radians(90) - pi/2}"/></xacro:rod>
  <xacro:if value="${len(tags) == 2 and math.sqrt(4) == 2}"><link name="kept"/></xacro:if>
  <xacro:unless value="true"><link name="dropped"/></xacro:unless>""",
    )
    root = _load(path)
    assert _names(root) == ["left_B", "kept"]
    assert root.find("link/visual/geometry/box").get("size") == "0.1 0.1 0.5"
    assert _names(_load(path, xacro_args=(("side", "right"),)))[0] == "right_B"


@pytest.mark.parametrize(
    ("expression", "shown"),
    [
        ("python.vars(python.type)['__subclasses__']", "python.vars"),
        ("''.__class__.__mro__", "''.__class__"),
        ("[].__class__", "[].__class__"),
        ("str.mro()", "str.mro"),
        ("python.getattr(1, 'real')", "python.getattr"),
        ("'%s'.format(1)", "'%s'.format"),
    ],
)
def test_python_object_access_is_refused_in_one_line(tmp_path, expression, shown):
    path = _xacro(tmp_path, f'  <link name="a"/>\n  <link name="${{{expression}}}"/>')
    with pytest.raises(SpecError) as err:
        _load(path)
    text = str(err.value)
    assert text.startswith(f"{path}:4: xacro expression: Python object access refused: ")
    assert shown in text and "\n" not in text


def test_trust_xacro_restores_the_full_evaluator(tmp_path):
    path = _xacro(tmp_path, '  <link name="n_${python.isinstance(1, python.int)}"/>')
    with pytest.raises(SpecError, match=r"Python object access refused: 'python\.isinstance'"):
        _load(path)
    assert _names(_load(path, trust_xacro=True)) == ["n_True"]


def test_environment_is_read_only_when_allowed(tmp_path, monkeypatch):
    monkeypatch.setenv("SIMKIT_SECRET", "s3cret")
    env = _xacro(tmp_path, '  <link name="e_$(env SIMKIT_SECRET)"/>', "env.xacro")
    with pytest.raises(SpecError, match=r"env\.xacro:3: .*\$\(env SIMKIT_SECRET\) refused"):
        _load(env)
    assert _names(_load(env, allow_env=("SIMKIT_SECRET",))) == ["e_s3cret"]
    opt = _xacro(tmp_path, '  <link name="o_$(optenv SIMKIT_SECRET fallback)"/>', "opt.xacro")
    assert _names(_load(opt)) == ["o_fallback"]  # set, but not allowed: the default
    assert _names(_load(opt, allow_env=("SIMKIT_SECRET",))) == ["o_s3cret"]


def test_files_outside_the_package_are_refused_unless_allowed(tmp_path):
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (outside / "part.xacro").write_text(HEAD + '  <link name="included"/>\n</robot>\n')
    (outside / "data.yaml").write_text("name: secret\n")
    inc = _xacro(tmp_path, f'  <xacro:include filename="{outside}/part.xacro"/>', "inc.xacro")
    with pytest.raises(SpecError, match=r"include .*part\.xacro refused: outside"):
        _load(inc)
    assert _names(_load(inc, allow_read=(outside,))) == ["included"]
    yml = _xacro(
        tmp_path,
        f"  <link name=\"${{xacro.load_yaml('{outside}/data.yaml')['name']}}\"/>",
        "yaml.xacro",
    )
    with pytest.raises(SpecError, match=r"load_yaml .*data\.yaml refused"):
        _load(yml)
    assert _names(_load(yml, allow_read=(outside,))) == ["secret"]


@pytest.mark.parametrize(
    ("body", "limit"),
    [
        ('  <link name="${9**9**9}"/>', "exponent too large"),
        ('  <link name="${1&lt;&lt;100000}"/>', "shift of 100000 bits is over the limit"),
        ("  <link name=\"${'a' * 10**8}\"/>", "repetition of 100000000 items is over the limit"),
        ('  <link name="${list(range(10**9))}"/>', "range of 1000000000 items is over the limit"),
        ("  <link name=\"${''.join(['a' * 10**6] * 100)}\"/>", "join() of 100000000 characters"),
        (
            "  <link name=\"${('a' * 10**6).replace('a', 'bb')}\"/>",
            "replace() of 2000000 characters",
        ),
        (
            '  <link name="${[[0] * 10**6 for i in range(100)]}"/>',
            "over the limit of 50000000 items",
        ),
        ('  <link name="${sum([[1]] * 10, [])}"/>', "sum() of non-numbers is not allowed"),
        ('  <link name="${' + "1+" * 6000 + '1}"/>', "characters is over the limit of 10000"),
        (
            '  <xacro:macro name="m" params="n"><xacro:m n="${n}"/><xacro:m n="${n}"/>'
            '</xacro:macro>\n  <xacro:m n="1"/>',
            "macro depth over the limit of 100",
        ),
    ],
    ids=lambda value: value if len(value) < 40 else value[:37] + "...",
)
def test_expansion_is_bounded_with_one_line_naming_the_limit(tmp_path, body, limit):
    path = _xacro(tmp_path, body)
    start = time.perf_counter()
    with pytest.raises(SpecError) as err:
        _load(path)
    assert limit in str(err.value) and "\n" not in str(err.value)
    assert str(err.value).startswith(f"{path}:3: ")
    assert time.perf_counter() - start < 30


def test_macro_calls_are_bounded(tmp_path, monkeypatch):
    """A macro expanding itself twice per level, 40 levels deep (2**40 calls): refused at
    the call limit (lowered here to keep the test fast; the default is 20,000)."""
    monkeypatch.setattr(xacro_safe, "MAX_MACRO_CALLS", 500)
    body = (
        '  <xacro:macro name="m" params="n"><xacro:if value="${n > 0}"><link name="x"/>'
        '<xacro:m n="${n-1}"/><xacro:m n="${n-1}"/></xacro:if></xacro:macro>\n'
        '  <xacro:m n="40"/>'
    )
    with pytest.raises(SpecError, match="over the limit of 500 macro calls in one expansion"):
        _load(_xacro(tmp_path, body))


def test_output_size_is_bounded(tmp_path, monkeypatch):
    monkeypatch.setattr(xacro_safe, "MAX_OUTPUT", 2000)
    path = _xacro(tmp_path, "".join(f'  <link name="l{i}"/>\n' for i in range(200)))
    with pytest.raises(SpecError, match="bytes is over the limit of 2000"):
        _load(path)


def test_xacro_is_left_as_it_was_after_a_refusal(tmp_path):
    import xacro

    before = (xacro.safe_eval, xacro.eval_extension, xacro.parse, xacro._global_symbols)
    with pytest.raises(SpecError):
        _load(_xacro(tmp_path, '  <link name="${python.vars(1)}"/>'))
    assert (xacro.safe_eval, xacro.eval_extension, xacro.parse, xacro._global_symbols) == before


def test_cli_refuses_an_evil_xacro_in_one_line(tmp_path):
    marker = tmp_path / "pwned"
    evil = (
        "python.vars(python.type)['__subclasses__'](python.object)"
        f"  # would reach os.system('touch {marker}')"
    )
    path = _xacro(tmp_path, f'  <link name="${{{evil}}}"/>')
    result = CliRunner().invoke(main, ["import", str(path), "--out", str(tmp_path / "out")])
    assert result.exit_code == 2
    assert "Python object access refused" in result.output and "Traceback" not in result.output
    assert len(result.output.strip().splitlines()) == 1
    assert not marker.exists() and not (tmp_path / "out" / "r.yaml").exists()


def test_malformed_xml_in_a_xacro_names_its_line(tmp_path):
    path = _xacro(tmp_path, '  <link name="a">\n  </joint>')
    with pytest.raises(SpecError) as err:
        _load(path)
    assert str(err.value).startswith(f"{path}:4: xacro: xacro expansion failed: mismatched tag")
