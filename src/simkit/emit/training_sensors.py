"""The base sensors a floating robot's Playground environment reads (issue 41).

MuJoCo Playground's locomotion examples observe the base's angular velocity (`gyro`), its
linear velocity in the base frame (`local_linvel`, a velocimeter) and its orientation (the
`upvector`, a frame z axis). A kit whose spec has them at its base link (a site on the
floating joint's child) uses its own; the others get them in the GPU scene, at a site at the
base link's origin, named as Playground names them. Arms need none: their observations are
the servo encoders (joint positions and velocities).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from simkit.kitio.xmlwriter import sub
from simkit.model.robot import Robot

#: role -> the MuJoCo sensor types that fill it (a frame quaternion also gives the up vector)
KINDS = {"gyro": ("gyro",), "local_linvel": ("velocimeter",), "orientation": ("framequat",)}
ROLES = ("gyro", "local_linvel", "orientation", "upvector")
#: the site and sensors the GPU scene adds where the spec has none at the base
SITE = "simkit_base_imu"
ADDED = {"gyro": "gyro", "local_linvel": "velocimeter", "upvector": "framezaxis"}


def _site(sensor) -> str | None:
    return (
        sensor.site
        if sensor.site is not None
        else (sensor.objname if sensor.objtype == "site" else None)
    )


def spec_sensors(robot: Robot) -> dict[str, str]:
    """role -> the name of the spec's own sensor at the base link, where it has one."""
    floating = robot.floating_joint
    if floating is None or robot.mjcf is None:
        return {}
    base_sites = {f.name for f in robot.frames if f.parent == floating.child}
    out: dict[str, str] = {}
    for sensor in robot.mjcf.sensors:
        if _site(sensor) not in base_sites:
            continue
        for role, kinds in KINDS.items():
            if sensor.type in kinds and role not in out:
                out[role] = sensor.name
    return out


def missing(robot: Robot) -> list[str]:
    """Roles the GPU scene must add (in ADDED's order); none for a fixed base."""
    if robot.floating_joint is None:
        return []
    have = spec_sensors(robot)
    need = [r for r in ("gyro", "local_linvel") if r not in have]
    return need + ([] if "orientation" in have else ["upvector"])


def base_sensors(robot: Robot) -> dict[str, str]:
    """role -> sensor name in the GPU scene, the spec's own or the added ones."""
    return {**spec_sensors(robot), **{role: role for role in missing(robot)}}


def add(robot: Robot, mujoco: ET.Element, worldbody: ET.Element) -> None:
    """Add the missing base sensors (and their site) to a GPU scene being written."""
    roles = missing(robot)
    if not roles:
        return
    body = worldbody.find(f".//body[@name='{robot.floating_joint.child}']")  # type: ignore[union-attr]
    if body is None:
        return
    sub(body, "site", name=SITE, size="0.005")
    sensor = mujoco.find("sensor")
    if sensor is None:
        sensor = sub(mujoco, "sensor")
    for role in roles:
        attrs = {"name": role, "site": SITE}
        if ADDED[role] == "framezaxis":
            attrs = {"name": role, "objtype": "site", "objname": SITE}
        sub(sensor, ADDED[role], attrs)
