"""The kit as a ROS 2 description package: package.xml, CMakeLists.txt, launch file, RViz."""

from __future__ import annotations

import ast
import re
import shutil
import xml.etree.ElementTree as ET

import yaml
from catkin_pkg.package import parse_package_string

from simkit.check import ros as ros_check
from simkit.check.kit import Kit
from simkit.kitio import layout


def test_package_xml_parses_and_validates(rosie_1000):
    package = parse_package_string((rosie_1000.kit_dir / "package.xml").read_text())
    package.validate()  # raises InvalidPackage on any error
    assert package.package_format == 3
    assert package.name == "rosie_1000_description" == rosie_1000.kit_dir.name
    assert [d.name for d in package.buildtool_depends] == ["ament_cmake"]
    assert package.get_build_type() == "ament_cmake"
    exec_depends = {d.name for d in package.exec_depends}
    assert {"robot_state_publisher", "joint_state_publisher_gui", "rviz2"} <= exec_depends
    assert not any("xacro" in d for d in exec_depends)


def test_cmakelists_installs_every_folder_that_exists(rosie_1000):
    text = (rosie_1000.kit_dir / "CMakeLists.txt").read_text()
    assert "project(rosie_1000_description)" in text
    assert "find_package(ament_cmake REQUIRED)" in text
    assert text.rstrip().endswith("ament_package()")
    loop = re.search(
        r"foreach\(dir ([^)]*)\)\s*if\(EXISTS \"\$\{CMAKE_CURRENT_SOURCE_DIR\}/"
        r"\$\{dir\}\"\)\s*install\(DIRECTORY \$\{dir\} DESTINATION "
        r"share/\$\{PROJECT_NAME\}\)",
        text,
    )
    assert loop, text
    installed = set(loop.group(1).split())
    folders = {p.name for p in rosie_1000.kit_dir.iterdir() if p.is_dir()}
    assert {"urdf", "mjcf", "srdf", "meshes", "launch", "rviz"} <= folders
    assert folders <= installed, f"not installed: {sorted(folders - installed)}"
    files = re.search(r"foreach\(file ([^)]*)\)", text).group(1).split()
    assert "robot.json" in files


def _constants(tree: ast.Module) -> dict[str, str]:
    """Module-level string constants, evaluated from the parsed launch file alone."""
    values: dict[str, str] = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name):
            expr = compile(ast.Expression(node.value), "<launch>", "eval")
            values[node.targets[0].id] = eval(expr, {"__builtins__": {}}, dict(values))
    return values


def test_launch_file_parses_and_rewrites_mesh_paths(rosie_1000):
    kit = rosie_1000.kit_dir
    tree = ast.parse((kit / layout.DISPLAY_LAUNCH).read_text())
    functions = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    assert "generate_launch_description" in functions
    strings = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)}
    assert {"robot_state_publisher", "joint_state_publisher_gui", "rviz2"} <= strings
    const = _constants(tree)
    assert const["PACKAGE"] == kit.name
    assert (kit / const["URDF"]).is_file() and (kit / const["RVIZ"]).is_file()
    # The rewrite the launch file applies, on the kit's own URDF.
    urdf = (kit / const["URDF"]).read_text()
    assert 'filename="../meshes/' in urdf
    rewritten = urdf.replace(const["RELATIVE_MESHES"], const["PACKAGE_MESHES"])
    uris = re.findall(r'filename="([^"]+)"', rewritten)
    assert uris and all(u.startswith(f"package://{kit.name}/meshes/") for u in uris)
    for uri in uris:
        assert (kit / uri.removeprefix(f"package://{kit.name}/")).is_file(), uri


def test_rviz_config_shows_robot_model_and_tf(rosie_1000):
    doc = yaml.safe_load((rosie_1000.kit_dir / layout.rviz("rosie_1000")).read_text())
    manager = doc["Visualization Manager"]
    classes = {d["Class"] for d in manager["Displays"]}
    assert {"rviz_default_plugins/RobotModel", "rviz_default_plugins/TF"} <= classes
    model = next(d for d in manager["Displays"] if d["Class"].endswith("RobotModel"))
    assert model["Description Topic"]["Value"] == "/robot_description"
    assert manager["Global Options"]["Fixed Frame"] == "base_footprint"


def test_build_check_finds_a_folder_cmakelists_does_not_install(rosie_1000, tmp_path):
    kit = tmp_path / rosie_1000.kit_dir.name
    shutil.copytree(rosie_1000.kit_dir, kit)
    assert [f.ok for f in ros_check.check_ros(Kit.open(kit)) if f.check == "ros2.cmakelists"] == [
        True
    ]
    (kit / "maps").mkdir()
    (kit / "maps" / "cell.yaml").write_text("{}\n")
    (kit / "NOTES.md").write_text("notes\n")
    (finding,) = [f for f in ros_check.check_ros(Kit.open(kit)) if f.check == "ros2.cmakelists"]
    assert not finding.ok and "maps/" in finding.detail and "NOTES.md" in finding.detail


def test_launch_file_robot_description_rewrites_every_mesh(rosie_1000, tmp_path):
    """Run the launch file's own robot_description() (not a copy of its logic) on an install
    prefix laid out as colcon installs the package: share/NAME/ holds what CMakeLists.txt
    installs. ROS is not installed here, so the ament index lookup is the one stand-in."""
    kit = rosie_1000.kit_dir
    text = (kit / layout.DISPLAY_LAUNCH).read_text()
    tree = ast.parse(text)
    const = _constants(tree)
    share = tmp_path / "install" / "share" / const["PACKAGE"]
    shutil.copytree(kit, share)

    def get_package_share_directory(package: str) -> str:
        if package != const["PACKAGE"]:
            raise LookupError(package)
        return str(share)

    keep = [
        n
        for n in tree.body
        if isinstance(n, ast.Assign)
        or (isinstance(n, ast.FunctionDef) and n.name == "robot_description")
        or (isinstance(n, ast.Import) and all(a.name == "os" for a in n.names))
    ]
    namespace = {"get_package_share_directory": get_package_share_directory}
    exec(compile(ast.Module(body=keep, type_ignores=[]), "display.launch.py", "exec"), namespace)
    description = namespace["robot_description"]()
    assert "../meshes/" not in description
    uris = re.findall(r'filename="([^"]+)"', description)
    assert len(uris) >= 7
    for uri in uris:
        assert uri.startswith(f"package://{const['PACKAGE']}/meshes/"), uri
        assert (share / uri.removeprefix(f"package://{const['PACKAGE']}/")).is_file(), uri
    ET.fromstring(description)  # still a well-formed URDF
