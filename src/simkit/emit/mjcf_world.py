"""MJCF parts that follow the spec's optional `mjcf:` section (`spec_mjcf.MjcfSpec`): visual
settings, default classes, textured materials, floor, lights, cameras, sensors, joint-limit
contact, and whether the servos live in the main file or in the scene file.

`emit.mjcf` calls these; each writes nothing when the spec leaves its part out, so kits
without an `mjcf:` section are unchanged. Attribute names and units are MuJoCo's (MuJoCo XML
reference): lengths in m, angles of cameras and the free camera in degrees.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from pydantic import BaseModel

from simkit.kitio.fmt import num, vec
from simkit.kitio.xmlwriter import sub
from simkit.model.robot import Joint, Robot


def attrs_of(obj: BaseModel | None, exclude: tuple[str, ...] = ()) -> dict[str, str]:
    """MJCF attributes from a spec object, in field order: None left out, booleans as
    `true`/`false`, numbers through `fmt.num`, tuples through `fmt.vec`."""
    out: dict[str, str] = {}
    if obj is None:
        return out
    for name in type(obj).model_fields:
        value = getattr(obj, name)
        if name in exclude or value is None or isinstance(value, BaseModel):
            continue
        if isinstance(value, bool):
            out[name] = "true" if value else "false"
        elif isinstance(value, int | float):
            out[name] = num(value)
        elif isinstance(value, tuple):
            out[name] = vec(value)
        else:
            out[name] = str(value)
    return out


def timestep(robot: Robot, default: float) -> float:
    """Integration step (s): the spec's, else `default`."""
    return robot.mjcf.timestep if robot.mjcf is not None else default


def servos_in_main(robot: Robot) -> bool:
    """True when the position servos go into the main MJCF file (simkit's default)."""
    return robot.mjcf is None or robot.mjcf.actuators == "main"


def visual(robot: Robot, mujoco: ET.Element) -> None:
    """`<visual>`: global (offscreen size, free camera angles), headlight and haze."""
    spec = robot.mjcf.visual if robot.mjcf is not None else None
    if spec is None:
        return
    el = sub(mujoco, "visual")
    glob = attrs_of(spec, exclude=("haze",))
    if glob:
        sub(el, "global", glob)
    if spec.headlight is not None:
        sub(el, "headlight", attrs_of(spec.headlight))
    if spec.haze is not None:
        sub(el, "rgba", haze=vec(spec.haze))


def _merge(parent: ET.Element, tag: str, attrs: dict[str, str]) -> None:
    """Set `attrs` on the `tag` child of a default class, creating it if needed."""
    if not attrs:
        return
    child = parent.find(tag)
    if child is None:
        child = ET.Element(tag)
        parent.insert(0, child)
    for key, value in attrs.items():
        child.set(key, value)


def defaults(robot: Robot, robot_class: ET.Element, builtin: dict[str, ET.Element]) -> None:
    """The spec's default classes, nested in the robot's class (or in `parent`); a class named
    like a built-in one (`visual`, `collision`) adds its attributes to that class."""
    if robot.mjcf is None:
        return
    classes = dict(builtin)
    for cls in robot.mjcf.defaults:
        el = classes.get(cls.name)
        if el is None:
            parent = classes[cls.parent] if cls.parent else robot_class
            el = sub(parent, "default", {"class": cls.name})
            classes[cls.name] = el
            for tag, spec in (("joint", cls.joint), ("geom", cls.geom)):
                if spec is not None:
                    sub(el, tag, attrs_of(spec))
        else:
            _merge(el, "geom", attrs_of(cls.geom))
            _merge(el, "joint", attrs_of(cls.joint))


def assets(robot: Robot, asset: ET.Element) -> None:
    """Textures and MJCF-only materials (the textured floor...)."""
    if robot.mjcf is None:
        return
    for texture in robot.mjcf.textures:
        sub(asset, "texture", attrs_of(texture))
    for material in robot.mjcf.materials:
        sub(asset, "material", attrs_of(material))


def world(robot: Robot, worldbody: ET.Element) -> bool:
    """Lights and floor in the world body; False when the spec gives no lights (the caller
    then writes its default light)."""
    if robot.mjcf is None:
        return False
    for light in robot.mjcf.lights:
        sub(worldbody, "light", attrs_of(light))
    floor = robot.mjcf.floor
    if floor is not None:
        attrs = {"name": floor.name, "type": "plane", **attrs_of(floor, exclude=("name",))}
        sub(worldbody, "geom", attrs)
    cameras(robot, worldbody, None)
    return bool(robot.mjcf.lights)


def cameras(robot: Robot, body: ET.Element, link: str | None) -> None:
    """Cameras that ride on `link` (None: the world)."""
    if robot.mjcf is None:
        return
    for cam in robot.mjcf.cameras:
        if cam.body == link:
            sub(body, "camera", attrs_of(cam, exclude=("body", "estimated")))


def joint_extras(joint: Joint, attrs: dict[str, str]) -> None:
    """Default class and joint-limit contact (solreflimit, solimplimit, margin)."""
    if joint.mjcf_class is not None:
        attrs["class"] = joint.mjcf_class
    if joint.solreflimit is not None:
        attrs["solreflimit"] = vec(joint.solreflimit)
    if joint.solimplimit is not None:
        attrs["solimplimit"] = vec(joint.solimplimit)
    if joint.margin:
        attrs["margin"] = num(joint.margin)


def sensors(robot: Robot, mujoco: ET.Element) -> None:
    """`<sensor>`: one element per spec sensor, named by its type."""
    if robot.mjcf is None or not robot.mjcf.sensors:
        return
    el = sub(mujoco, "sensor")
    for sensor in robot.mjcf.sensors:
        sub(el, sensor.type, attrs_of(sensor, exclude=("type",)))
