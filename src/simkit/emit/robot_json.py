"""robot.json: the kit page's robot.json table, one machine-readable file for every number."""

from __future__ import annotations

import math
from importlib import metadata

from simkit import __version__, inertia_decision, layout
from simkit.emit import mjcf_world
from simkit.jsonout import dumps
from simkit.model import Joint, Link, Robot
from simkit.solids import CIRCULAR_SEGMENTS

LIBRARIES = ("numpy", "manifold3d", "trimesh", "coacd", "mujoco", "usd-core")


def _deg(value: float | None) -> float | None:
    return None if value is None else math.degrees(value)


def _joint(joint: Joint, extra: dict | None = None) -> dict:
    out: dict = {
        "name": joint.name,
        "type": joint.type,
        "parent": joint.parent,
        "child": joint.child,
        "origin_xyz": list(joint.xyz),
        "origin_rpy": list(joint.rpy),
        "axis": list(joint.axis),
        "lower": joint.lower,
        "upper": joint.upper,
        "lower_deg": _deg(joint.lower),
        "upper_deg": _deg(joint.upper),
        "max_velocity": joint.max_velocity,
        "max_velocity_deg_s": _deg(joint.max_velocity),
        "effort_peak": joint.effort_peak,
        "effort_continuous": joint.effort_continuous,
        "drive_peak_torque_at_joint": joint.drive_peak_torque_at_joint,
        "armature": joint.armature,
        "damping": joint.damping,
        "friction": joint.friction,
        # derive-step additions, e.g. derived_max_acceleration (motion.py)
        **(extra or {}),
    }
    if joint.stiffness:
        out.update(stiffness=joint.stiffness, springref=joint.springref)
    if joint.drive is not None:
        d = joint.drive
        out["drive"] = {
            "motor": d.motor,
            "motor_peak_torque": d.motor_peak_torque,
            "rotor_inertia": d.rotor_inertia,
            "gearbox": d.gearbox,
            "gear_ratio": d.gear_ratio,
            "gear_inertia": d.gear_inertia,
            "efficiency": d.efficiency,
            "gear_max_output_torque": d.gear_max_output_torque,
            "armature_formula": "(rotor_inertia + gear_inertia) * gear_ratio^2",
            "peak_torque_formula": "min(motor_peak_torque * gear_ratio * efficiency, "
            "gear_max_output_torque)",
        }
    if joint.mimic is not None:
        leader, multiplier, offset = joint.mimic
        out["mimic"] = {"joint": leader, "multiplier": multiplier, "offset": offset}
    out["actuated"] = joint.actuated
    out["estimated"] = list(joint.estimated)
    return out


def _link(link: Link) -> dict:
    inertial = link.inertial
    ixx, iyy, izz, ixy, ixz, iyz = inertial.inertia if inertial else (0.0,) * 6
    out = {
        "name": link.name,
        "mass": link.mass,
        "com": list(inertial.com) if inertial else [0.0, 0.0, 0.0],
        "inertia": {"ixx": ixx, "iyy": iyy, "izz": izz, "ixy": ixy, "ixz": ixz, "iyz": iyz},
        "mesh": {
            "visual": layout.visual_mesh(link.name) if link.solid is not None else None,
            "collision": [layout.collision_mesh(link.name, i) for i in range(len(link.collision))],
        },
        "estimated": list(link.estimated),
    }
    if link.note:
        out["note"] = link.note
    if link.inertia_decision is not None:  # kept non-physical inertia: recorded, never silent
        out["inertia_decision"] = inertia_decision.record(link.inertia_decision)
    return out


def _frames(robot: Robot) -> dict:
    frames: dict = {robot.root: {"role": "root of the URDF; the floor or mounting face"}}
    for joint in robot.joints:
        if joint.parent == robot.root:
            frames[joint.child] = {
                "parent": robot.root,
                "xyz": list(joint.xyz),
                "rpy": list(joint.rpy),
                "height": joint.xyz[2],
            }
    for frame in robot.frames:
        frames[frame.name] = {
            "parent": frame.parent,
            "xyz": list(frame.xyz),
            "rpy": list(frame.rpy),
        }
    return frames


def _versions() -> dict:
    out = {}
    for name in LIBRARIES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def document(robot: Robot) -> dict:
    """The robot.json content as plain data (other emitters extend it via `robot.derived`)."""
    published = robot.published
    poses = {name: list(q) for name, q in robot.poses}
    geometric = robot.derived.get("reach_geometric")
    doc: dict = {
        "name": robot.name,
        "title": robot.title,
        "description": robot.description,
        "units": {"length": "m", "mass": "kg", "angle": "rad", "time": "s", "torque": "N m"},
        "files": {
            "urdf": layout.urdf(robot.name),
            "mjcf": layout.mjcf(robot.name),
            "glb": layout.glb(robot.name),
        },
        "base_frame": robot.derived.get("base_frame", robot.root),
        "tool_frame": robot.tool_frame,
        "wrist_centre": robot.wrist_centre,
        "joints": [
            _joint(j, robot.derived.get("joint_json", {}).get(j.name)) for j in robot.movable_joints
        ],
        "fixed_joints": [
            {
                "name": j.name,
                "parent": j.parent,
                "child": j.child,
                "origin_xyz": list(j.xyz),
                "origin_rpy": list(j.rpy),
            }
            for j in robot.joints
            if j.type == "fixed"
        ],
        "links": [_link(link) for link in robot.links],
        "frames": _frames(robot),
        "home": poses.get("home"),
        "poses": poses,
        "fk_reference": robot.derived.get("fk_reference", []),
        "reach": {
            "published": {
                "wrist": published.get("reach_wrist"),
                "flange": published.get("reach_flange"),
            },
            "geometric": geometric,
            "note": "geometric reach: distance of the wrist centre and of tool0 from the J1 axis "
            "at the stretched pose",
        },
        "payload": {
            "rated": published.get("payload"),
            "estimate": "payload" in robot.published_estimated,
        },
        "repeatability_mm": published.get("repeatability_mm"),
        "published": published,
        "mass": {"published": published.get("mass"), "model": robot.total_mass},
        "geometry": {
            "method": "each link is one filled solid: the union of the spec's primitives "
            f"(manifold3d, {CIRCULAR_SEGMENTS} segments per circle); motors and gearboxes are "
            "plain envelopes",
            "mass_properties": "CoM and inertia of the solid at uniform density scaled to the "
            "link mass, unless the spec gives them",
            "collision": robot.derived.get("geometry_collision"),
            "links": robot.derived.get("geometry_links", []),
        },
        "actuators": [
            {
                "joint": a.joint,
                "type": "position",
                "kp": a.kp,
                "kv": a.kv,
                "forcerange": a.forcerange,
            }
            for a in robot.actuators
        ],
        "provenance": {
            "spec": robot.spec_file,
            "spec_sha256": robot.spec_sha256,
            "simkit_version": __version__,
            "libraries": _versions(),
            "seeds": {"spec": robot.seed, **robot.derived.get("seeds", {})},
            "sources": list(robot.sources),
            "published_estimated": list(robot.published_estimated),
        },
    }
    _generalise(robot, doc)
    doc.update(robot.derived.get("robot_json", {}))
    return doc


def _generalise(robot: Robot, doc: dict) -> None:
    """Drop the arm-only entries where they do not apply (no wrist centre or tool frame, no
    payload or repeatability published) and add a floating base, the MJCF scene file and the
    MJCF sensors where the spec has them. Arm kits are unchanged."""
    if not (robot.wrist_centre or robot.tool_frame):
        doc.pop("fk_reference")
        if not robot.derived.get("reach_geometric") and not doc["reach"]["published"]["wrist"]:
            doc.pop("reach")
    if doc["payload"]["rated"] is None:
        doc.pop("payload")
    if doc["repeatability_mm"] is None:
        doc.pop("repeatability_mm")
    floating = robot.floating_joint
    if floating is not None:
        doc["floating_base"] = {
            "joint": floating.name,
            "parent": floating.parent,
            "child": floating.child,
            "origin_xyz": list(floating.xyz),
            "origin_rpy": list(floating.rpy),
            "note": "MJCF free joint; the URDF's root is the child link (no world joint); "
            "MuJoCo qpos starts with its position (m) and quaternion (w, x, y, z)",
        }
        doc["frames"][robot.root]["role"] = "the world; the floating base moves freely in it"
    if not mjcf_world.servos_in_main(robot):
        doc["files"]["mjcf_scene"] = layout.mjcf_scene(robot.name)
    if robot.mjcf is not None and robot.mjcf.sensors:
        doc["sensors"] = [s.model_dump(exclude_none=True) for s in robot.mjcf.sensors]


def emit(robot: Robot) -> dict[str, bytes]:
    """`robot.json`."""
    return {layout.ROBOT_JSON: dumps(document(robot))}
