"""MJCF report lines and refusals name the line (issue 31): each record points at the line
of the body, joint or geom it is about (MuJoCo's parser records it), a named element read
from an `<include>` at the `<include>` in the model file (an unnamed one, which would share
that line with all the include brings in, at none), and a refusal about a body at its line."""

from __future__ import annotations

import pytest

from mjcf_models import INERTIAL, write
from simkit.errors import SpecError
from simkit.importer import import_robot

MAIN = f"""<mujoco model="arm">
  <compiler angle="radian"/>
  <worldbody>
    <body name="base">{INERTIAL}
      <geom type="box" size="0.03 0.03 0.1" pos="0 0 0.1"/>
      <body name="link1" pos="0 0 0.2">
        <joint name="j1" axis="0 1 0" range="-1 1"/>
        {INERTIAL}
        <geom name="upper" type="box" size="0.03 0.03 0.1" pos="0 0 0.1"/>
        <include file="part.xml"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""
PART = f"""<mujoco>
  <body name="link2" pos="0 0 0.2">
    <joint name="j2" axis="0 1 0" range="-1 1"/>
    {INERTIAL}
    <geom type="box" size="0.03 0.03 0.1" pos="0 0 0.1"/>
  </body>
</mujoco>
"""


def _by_element(lines: tuple[str, ...]) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for line in lines:
        where, element = line.split(": ")[:2]
        out.setdefault(element, []).append(where)
    return out


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    folder = tmp_path_factory.mktemp("lines")
    write(folder, PART, "part.xml")
    done = import_robot(write(folder, MAIN), folder / "out")
    return _by_element(done.lines)


def test_no_record_about_the_model_file_lacks_its_line(report):
    assert not [w for e, where in report.items() for w in where if w.endswith(":?") and "[" in e]
    assert report["limit"].count("model.xml:?") == len(report["limit"]) / 2  # j2's: included


def test_each_record_names_its_element_s_line(report):
    assert report["robot[arm]"] == ["model.xml:4"]  # the root body
    assert report["link[link1]"] == ["model.xml:6"]
    assert "model.xml:7" in report["limit"]  # j1's estimated limits


def test_an_included_element_is_named_at_its_include(report):
    assert report["link[link2]"] == ["model.xml:10"]
    assert set(report["limit"]) == {"model.xml:7", "model.xml:?"}


def test_a_refusal_about_a_second_robot_names_its_body_s_line(tmp_path):
    two = MAIN.replace(
        "  </worldbody>",
        f'    <body name="other"><joint name="k" axis="1 0 0"/>{INERTIAL}</body>\n  </worldbody>',
    )
    write(tmp_path, PART, "part.xml")
    with pytest.raises(SpecError) as err:
        import_robot(write(tmp_path, two), tmp_path / "out")
    assert str(err.value).startswith(f"{tmp_path / 'model.xml'}:13: worldbody: several robots")
