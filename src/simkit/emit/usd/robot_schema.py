"""Isaac Sim's robot schema (isaacsim.robot.schema, `IsaacRobotAPI`) on the default prim:
`isaac:physics:robotLinks` (every link, tree order), `isaac:physics:robotJoints` (every joint,
tree order, so the first is the root joint that SimReady RC.009 reads), `isaac:robotType`, and
`IsaacLinkAPI` / `IsaacJointAPI` on the links and joints. Written as plain tokens: the schema
plugin is Isaac Sim's, and usd-core keeps unknown applied schemas as authored."""

from __future__ import annotations

from simkit.emit.ros2 import default_license
from simkit.emit.usd.common import prim_name
from simkit.model.robot import Robot

#: isaac:license's allowed tokens (IsaacRobotAPI); any other licence is "Other"
LICENSES = (
    "MIT",
    "Apache-2.0",
    "GPL-3.0",
    "LGPL-3.0",
    "BSD-3-Clause",
    "BSD-2-Clause",
    "ISC",
    "MPL-2.0",
    "EPL-2.0",
    "CC0-1.0",
    "Unlicense",
)


def _limbs(robot: Robot, start: str) -> list[int]:
    """Movable joints per branch leaving link `start` (a branch: one child subtree)."""
    children: dict[str, list] = {}
    for joint in robot.joints:
        children.setdefault(joint.parent, []).append(joint)

    def movable(link: str) -> int:
        return sum(j.movable + movable(j.child) for j in children.get(link, []))

    return [j.movable + movable(j.child) for j in children.get(start, [])]


def robot_type(robot: Robot) -> str:
    """Isaac Sim's robot type by rule. Fixed to the world: "Manipulator" (Isaac pins the root
    joint of manipulators and end effectors only, SimReady RC.009). A floating base: its limbs
    are the branches off the floating link that hold at least two movable joints; four limbs
    or more make a "Quadruped", two or three a "Humanoid" (a biped, arms or not); continuous
    joints without limbs make "Wheeled", and a floating body with neither is "Aerial"."""
    floating = robot.floating_joint
    if floating is None:
        return "Manipulator"
    limbs = [n for n in _limbs(robot, floating.child) if n >= 2]
    if len(limbs) >= 4:
        return "Quadruped"
    if len(limbs) >= 2:
        return "Humanoid"
    if any(j.type == "continuous" for j in robot.joints):
        return "Wheeled"
    return "Aerial"


def apply_robot_schema(stage, top, robot: Robot, joints: list[str]) -> None:
    """IsaacRobotAPI on `top`, IsaacLinkAPI on every link and IsaacJointAPI on `joints`."""
    from pxr import Sdf

    root = str(top.GetPath())
    top.AddAppliedSchema("IsaacRobotAPI")
    links = [f"{root}/{prim_name(link.name)}" for link in robot.links]
    for rel, targets in (("robotLinks", links), ("robotJoints", joints)):
        relationship = top.CreateRelationship(f"isaac:physics:{rel}", custom=False)
        for target in targets:  # prepended, in order, as Isaac Sim authors them (DJ.010)
            relationship.AddTarget(target)
    token = Sdf.ValueTypeNames.Token
    top.CreateAttribute("isaac:robotType", token, custom=False).Set(robot_type(robot))
    spdx = robot.license or default_license(robot)
    top.CreateAttribute("isaac:license", token, custom=False).Set(
        spdx if spdx in LICENSES else "Other"
    )
    text = Sdf.ValueTypeNames.String
    top.CreateAttribute("isaac:description", text, custom=False).Set(robot.description)
    top.CreateAttribute("isaac:source", text, custom=False).Set(robot.spec_file)
    for path in links:
        stage.GetPrimAtPath(path).AddAppliedSchema("IsaacLinkAPI")
    for path in joints:
        stage.GetPrimAtPath(path).AddAppliedSchema("IsaacJointAPI")
