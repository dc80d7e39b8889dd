"""The ROS side of a written kit: package.xml, the launch file and the SRDF agree with the URDF.

Reads the files as ROS tools would (plain XML and Python parsing, no ROS install needed).
Kit page: "launch/ rviz/ package.xml CMakeLists.txt ROS 2 package NAME_description" and
"srdf/NAME.srdf planning group, named poses, disabled collision pairs (MoveIt)".
"""

from __future__ import annotations

import ast
import re
import xml.etree.ElementTree as ET

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.kitio import layout

NEEDED_EXEC_DEPENDS = {"robot_state_publisher", "joint_state_publisher_gui", "rviz2"}


def _package(kit: Kit) -> list[Finding]:
    path = kit.path(layout.PACKAGE_XML)
    if not path.is_file():
        return [require("ros2.package_xml", False, "package.xml is missing")]
    root = ET.parse(path).getroot()
    name = root.findtext("name")
    depends = {e.text for e in root.iter("exec_depend")}
    return [
        require("ros2.package_xml.format", root.get("format") == "3", "package.xml format 3"),
        require(
            "ros2.package_xml.name",
            name == layout.kit_dir_name(kit.name),
            f"package name {name!r} is {layout.kit_dir_name(kit.name)!r}",
        ),
        require(
            "ros2.package_xml.build_type",
            root.findtext("export/build_type") == "ament_cmake",
            "build type ament_cmake",
        ),
        require(
            "ros2.package_xml.exec_depends",
            depends >= NEEDED_EXEC_DEPENDS,
            f"exec_depends include {sorted(NEEDED_EXEC_DEPENDS)}",
        ),
    ]


#: `foreach(VAR a b c)` whose body installs `${VAR}` as a DIRECTORY or FILES, and plain
#: `install(DIRECTORY|FILES a b c DESTINATION ...)`.
_LOOP = re.compile(r"foreach\((\w+)\s+([^)]*)\)(.*?)endforeach\(\)", re.S)
_INSTALL = re.compile(r"install\((DIRECTORY|FILES)\s+([^)]*?)\s+DESTINATION", re.S)


def installed_paths(text: str) -> dict[str, set[str]]:
    """{"DIRECTORY": names, "FILES": names} that a CMakeLists.txt installs."""
    out: dict[str, set[str]] = {"DIRECTORY": set(), "FILES": set()}
    for var, items, body in _LOOP.findall(text):
        for kind, args in _INSTALL.findall(body):
            if args.split() == [f"${{{var}}}"]:
                out[kind] |= set(items.split())
    for kind, args in _INSTALL.findall(_LOOP.sub("", text)):
        out[kind] |= set(args.split())
    return out


def _cmakelists(kit: Kit) -> list[Finding]:
    """CMakeLists.txt installs every folder and top-level file of the kit (package.xml and
    CMakeLists.txt itself aside), so `colcon build` ships all of it."""
    path = kit.path(layout.CMAKELISTS)
    if not path.is_file():
        return [require("ros2.cmakelists", False, f"{layout.CMAKELISTS} is missing")]
    installed = installed_paths(path.read_text(encoding="utf-8"))
    own = {layout.PACKAGE_XML, layout.CMAKELISTS}
    missing = sorted(
        p.name + ("/" if p.is_dir() else "")
        for p in kit.root.iterdir()
        if not p.name.startswith(".") and p.name != "__pycache__"  # a user's, not the kit's
        if (p.is_dir() and p.name not in installed["DIRECTORY"])
        or (p.is_file() and p.name not in own and p.name not in installed["FILES"])
    )
    return [
        require(
            "ros2.cmakelists",
            not missing,
            f"{layout.CMAKELISTS} does not install {missing}"
            if missing
            else f"{layout.CMAKELISTS} installs every folder and file of the kit",
        )
    ]


def _launch(kit: Kit) -> list[Finding]:
    path = kit.path(layout.DISPLAY_LAUNCH)
    if not path.is_file():
        return [require("ros2.launch", False, f"{layout.DISPLAY_LAUNCH} is missing")]
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except SyntaxError as exc:
        return [require("ros2.launch", False, f"{layout.DISPLAY_LAUNCH} does not parse: {exc}")]
    strings = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)}
    return [
        require(
            "ros2.launch",
            kit.urdf in strings and layout.kit_dir_name(kit.name) in strings,
            f"{layout.DISPLAY_LAUNCH} parses and loads {kit.urdf}",
        )
    ]


def _srdf(kit: Kit) -> list[Finding]:
    path = kit.path(layout.srdf(kit.name))
    if not path.is_file():
        return [require("srdf", False, f"{layout.srdf(kit.name)} is missing")]
    srdf = ET.parse(path).getroot()
    urdf = ET.parse(kit.path(kit.urdf)).getroot()
    links = {link.get("name") for link in urdf.iter("link")}
    solid = {link.get("name") for link in urdf.iter("link") if link.find("collision") is not None}
    limits = {}
    # top-level joints only: <transmission> and <ros2_control> nest <joint> elements too
    for joint in urdf.findall("joint"):
        limit = joint.find("limit")
        if limit is not None and limit.get("lower") is not None:
            limits[joint.get("name")] = (float(limit.get("lower")), float(limit.get("upper")))
        elif joint.get("type") != "fixed":
            limits[joint.get("name")] = (float("-inf"), float("inf"))
    named = [
        e.get(a)
        for e in srdf.iter()
        for a in ("base_link", "tip_link", "parent_link", "child_link", "link1", "link2")
        if e.get(a) is not None
    ]
    named += [e.get("name") for g in srdf.iter("group") for e in g.iter("link")]
    unknown = sorted(set(named) - links)
    outside = [
        f"{state.get('name')}:{j.get('name')}"
        for state in srdf.iter("group_state")
        for j in state.iter("joint")
        if j.get("name") not in limits
        or not limits[j.get("name")][0] - 1e-9
        <= float(j.get("value"))
        <= limits[j.get("name")][1] + 1e-9
    ]
    disabled = {
        frozenset((d.get("link1"), d.get("link2"))) for d in srdf.iter("disable_collisions")
    }
    adjacent = {
        frozenset((j.find("parent").get("link"), j.find("child").get("link")))
        for j in urdf.findall("joint")
    }
    missing = sorted(tuple(sorted(p)) for p in adjacent if p <= solid and p not in disabled)
    return [
        require(
            "srdf.links",
            not unknown,
            f"links the SRDF names that the URDF lacks: {unknown}"
            if unknown
            else "every link the SRDF names is in the URDF",
        ),
        require(
            "srdf.group_states",
            not outside,
            f"group states outside the URDF limits or joints: {outside[:3]}"
            if outside
            else "group states within the URDF limits",
        ),
        require(
            "srdf.adjacent_disabled",
            not missing,
            f"adjacent pairs not disabled: {missing}"
            if missing
            else "every adjacent link pair is disabled",
        ),
    ]


def check_ros(kit: Kit) -> list[Finding]:
    """package.xml, CMakeLists.txt, launch/display.launch.py and the SRDF against the URDF."""
    return _package(kit) + _cmakelists(kit) + _launch(kit) + _srdf(kit)
