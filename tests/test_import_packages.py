"""Mesh resolution as the field does it (issue 22) and confinement to the robot's package
(issue 24): a flattened `package://` found by its path's tail under the package root, one
report line naming the file; ambiguity and paths outside the package are one-line errors."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from simkit.errors import SpecError
from simkit.importer import formats, import_robot
from simkit.importer.diagnostics import Report
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.packages import MissingMesh, PackageMap, package_root
from simkit.importer.read.source import resolve_uri

STL = Path(__file__).resolve().parent / "specs" / "urdf" / "pkg_demo" / "meshes" / "bracket.stl"


def _robot(uri: str) -> str:
    return f"""<?xml version="1.0"?>
<robot name="r">
  <link name="base">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="{uri}"/></geometry></visual>
  </link>
</robot>
"""


def _write(path: Path, text: str | None = None) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if text is None:
        shutil.copy(STL, path)
    else:
        path.write_text(text)
    return path


def _lines(urdf: Path, **options) -> tuple[str, ...]:
    report = Report()
    doc = formats.load(urdf, (), report, ReadOptions(**options))
    mesh = doc.root.find("link/visual/geometry/mesh")
    resolve_uri(doc, mesh, mesh.get("filename"))
    return tuple(report.lines)


def test_package_root_is_the_nearest_package_or_the_folder_above(tmp_path):
    _write(tmp_path / "a" / "package.xml", "<package><name>a</name></package>")
    assert package_root(tmp_path / "a" / "urdf" / "deep" / "r.urdf") == tmp_path / "a"
    assert package_root(tmp_path / "b" / "urdf" / "r.urdf") == tmp_path / "b"


def test_a_flattened_package_uri_is_found_by_its_tail(tmp_path):
    urdf = _write(tmp_path / "robot" / "urdf" / "r.urdf", _robot("package://visual/BASE.stl"))
    _write(tmp_path / "robot" / "meshes" / "robot" / "visual" / "BASE.stl")
    _write(tmp_path / "robot" / "meshes" / "robot" / "collision" / "BASE.stl", "other bytes")
    done = import_robot(urdf, tmp_path / "out")
    assert done.meshes == 1
    assert (
        "r.urdf:6: mesh: changed: package://visual/BASE.stl not found as given: using "
        "../meshes/robot/visual/BASE.stl, found by its path's tail under the robot's package "
        "root" in done.lines
    )


def test_a_package_prefix_that_names_folders_above_is_dropped(tmp_path):
    uri = "package://drake/examples/mybot/urdf/meshes/part.stl"
    urdf = _write(tmp_path / "mybot" / "urdf" / "mybot.urdf", _robot(uri))
    _write(tmp_path / "mybot" / "urdf" / "meshes" / "part.stl")
    assert "using meshes/part.stl" in _lines(urdf)[0]


def test_two_differing_candidates_are_an_error_naming_both(tmp_path):
    urdf = _write(tmp_path / "robot" / "urdf" / "r.urdf", _robot("package://gone/part.stl"))
    _write(tmp_path / "robot" / "meshes" / "a" / "part.stl")
    _write(tmp_path / "robot" / "meshes" / "b" / "part.stl", "solid other\nendsolid other\n")
    with pytest.raises(SpecError) as err:
        import_robot(urdf, tmp_path / "out")
    text = str(err.value)
    assert text.startswith(f"{urdf}:6: mesh: package://gone/part.stl is not where it says")
    assert "meshes/a/part.stl and meshes/b/part.stl" in text and "\n" not in text


def test_identical_candidates_are_one_file(tmp_path):
    urdf = _write(tmp_path / "robot" / "urdf" / "r.urdf", _robot("package://gone/part.stl"))
    _write(tmp_path / "robot" / "meshes" / "b" / "part.stl")
    _write(tmp_path / "robot" / "meshes" / "a" / "part.stl")
    assert "using ../meshes/a/part.stl" in _lines(urdf)[0]


def test_the_search_never_looks_above_the_package_root(tmp_path):
    _write(tmp_path / "part.stl")  # above the root: not a candidate
    _write(tmp_path / "robot" / "package.xml", "<package><name>robot</name></package>")
    urdf = _write(tmp_path / "robot" / "urdf" / "r.urdf", _robot("package://gone/part.stl"))
    packages = PackageMap(urdf)
    assert packages.root == tmp_path / "robot"
    with pytest.raises(MissingMesh, match="unknown package 'gone'"):
        packages.resolve("package://gone/part.stl", (str(urdf), 5, "mesh"))


@pytest.mark.parametrize("kind", ["relative", "file"])
def test_a_plain_path_outside_the_package_is_refused_unless_allowed(tmp_path, kind):
    outside = _write(tmp_path / "secret" / "part.stl")
    uri = "../../../secret/part.stl" if kind == "relative" else f"file://{outside}"
    urdf = _write(tmp_path / "robot" / "pkg" / "urdf" / "r.urdf", _robot(uri))
    _write(tmp_path / "robot" / "pkg" / "package.xml", "<package><name>pkg</name></package>")
    with pytest.raises(SpecError) as err:
        import_robot(urdf, tmp_path / "out")
    assert str(err.value).startswith(f"{urdf}:6: mesh: {uri} lies outside the robot's package root")
    assert "--allow-read" in str(err.value)
    done = import_robot(urdf, tmp_path / "out", reading=ReadOptions(allow_read=(outside.parent,)))
    assert done.meshes == 1


def test_a_package_found_through_package_dir_may_lie_anywhere(tmp_path):
    shared = tmp_path / "ws" / "parts_pkg"
    _write(shared / "package.xml", "<package><name>parts_pkg</name></package>")
    _write(shared / "meshes" / "part.stl")
    urdf = _write(
        tmp_path / "robot" / "urdf" / "r.urdf", _robot("package://parts_pkg/meshes/part.stl")
    )
    done = import_robot(urdf, tmp_path / "out", package_dirs=(tmp_path / "ws",))
    assert done.meshes == 1 and not any("not found as given" in x for x in done.lines)


def test_a_package_uri_may_not_climb_out_of_its_package(tmp_path):
    secret = _write(tmp_path / "secret.stl")
    shared = tmp_path / "ws" / "parts_pkg"
    _write(shared / "package.xml", "<package><name>parts_pkg</name></package>")
    uri = "package://parts_pkg/../../secret.stl"
    urdf = _write(tmp_path / "robot" / "urdf" / "r.urdf", _robot(uri))
    with pytest.raises(SpecError, match=r"r\.urdf:6: mesh: .* climbs out of package 'parts_pkg'"):
        import_robot(urdf, tmp_path / "out", package_dirs=(tmp_path / "ws",))
    reading = ReadOptions(allow_read=(secret.parent,))
    dirs = (tmp_path / "ws",)
    assert import_robot(urdf, tmp_path / "out", package_dirs=dirs, reading=reading).meshes == 1
