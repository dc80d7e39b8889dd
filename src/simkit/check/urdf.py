"""The URDF as ROS-side tools read it: yourdfpy parses, validates and agrees on FK."""

from __future__ import annotations

import logging

import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.fk import fk_agrees
from simkit.check.kit import Kit
from simkit.check.mujoco import random_configs

TOL = 1e-6  # both files carry 10 significant digits (fmt.num, jsonout)


def check_urdf(kit: Kit) -> list[Finding]:
    import yourdfpy  # lazy: pulls in trimesh

    logging.getLogger("yourdfpy").setLevel(logging.ERROR)
    path = kit.path(kit.urdf)
    try:
        urdf = yourdfpy.URDF.load(str(path), load_meshes=False, build_collision_scene_graph=False)
    except Exception as exc:  # yourdfpy raises several exception types on bad input
        return [require("urdf.yourdfpy", False, f"yourdfpy cannot load {kit.urdf}: {exc}")]
    findings = [require("urdf.yourdfpy.validate", urdf.validate(), "yourdfpy validates the URDF")]
    missing = [
        m.filename
        for link in urdf.robot.links
        for g in (link.visuals + link.collisions)
        if g.geometry.mesh is not None
        for m in [g.geometry.mesh]
        if not (path.parent / m.filename).is_file()
    ]
    findings.append(
        require(
            "urdf.meshes",
            not missing,
            f"mesh files missing: {missing[:3]}" if missing else "every mesh the URDF names exists",
        )
    )
    findings.extend(_joint_findings(kit, urdf))
    findings.extend(_carried_blocks(kit, path, urdf))
    tool = kit.doc.get("tool_frame")
    if tool:
        names = [j["name"] for j in kit.joints]

        def tool_pose(q: np.ndarray) -> np.ndarray:
            urdf.update_cfg(dict(zip(names, q, strict=True)))
            return urdf.get_transform(tool, kit.base_frame)

        configs = random_configs(kit, 10, seed=1)
        findings += fk_agrees(
            kit, "fk.yourdfpy_vs_robot_json", "yourdfpy", tool_pose, configs, 1e-6
        )
    return findings


def _joint_findings(kit: Kit, urdf) -> list[Finding]:
    """The URDF's <limit> and <dynamics> carry robot.json's numbers (kit page, "Simulation
    parameters": effort = effort_peak, velocity = the maximum joint speed)."""
    by_name = {j.name: j for j in urdf.robot.joints}
    movable = [j for j in kit.joints if j["type"] in ("revolute", "continuous", "prismatic")]
    missing = [j["name"] for j in movable if j["name"] not in by_name]
    if missing:
        return [require("urdf.joints", False, f"joints missing from the URDF: {missing}")]

    def read(name: str, part: str, attr: str, default: float) -> float:
        element = getattr(by_name[name], part)
        value = getattr(element, attr, None) if element is not None else None
        return default if value is None else float(value)

    limited = [j for j in movable if j["type"] != "continuous" and j["lower"] is not None]
    nan = float("nan")
    return [
        compare(
            "urdf.limits",
            "joint lower/upper vs robot.json",
            [[j["lower"], j["upper"]] for j in limited],
            [[read(j["name"], "limit", k, nan) for k in ("lower", "upper")] for j in limited],
            TOL,
            "rad or m",
            [j["name"] for j in limited],
        ),
        compare(
            "urdf.effort",
            "limit effort vs robot.json effort_peak",
            [j["effort_peak"] or 0.0 for j in movable],
            [read(j["name"], "limit", "effort", nan) for j in movable],
            TOL,
            "N m or N",
            [j["name"] for j in movable],
        ),
        compare(
            "urdf.velocity",
            "limit velocity vs robot.json max_velocity",
            [j["max_velocity"] or 0.0 for j in movable],
            [read(j["name"], "limit", "velocity", nan) for j in movable],
            TOL,
            "rad/s or m/s",
            [j["name"] for j in movable],
        ),
        compare(
            "urdf.dynamics",
            "joint damping and friction vs robot.json",
            [[j["damping"], j["friction"]] for j in movable],
            [
                [read(j["name"], "dynamics", k, 0.0) for k in ("damping", "friction")]
                for j in movable
            ],
            TOL,
            "SI",
            [j["name"] for j in movable],
        ),
    ]


def _carried_blocks(kit: Kit, path, urdf) -> list[Finding]:
    """robot.json `urdf_blocks` (an import's gazebo, transmission and ros2_control blocks)
    are the URDF's last top-level elements, in order, with the same canonical XML, and every
    link or joint they name is one yourdfpy read from the URDF."""
    import xml.etree.ElementTree as ET

    from simkit.spec import urdf_blocks

    recorded = kit.doc.get("urdf_blocks") or []
    if not recorded:
        return []
    written = list(ET.parse(path).getroot())[-len(recorded) :]
    texts = [ET.tostring(e, encoding="unicode") for e in written]
    same = (
        [
            w.tag == r["tag"] and urdf_blocks.digest(t) == r["sha256"]
            for w, t, r in zip(written, texts, recorded, strict=True)
        ]
        if len(written) == len(recorded)
        else []
    )
    known = {link.name for link in urdf.robot.links} | {j.name for j in urdf.robot.joints}
    named = [n for r in recorded for n in r["names"]]
    unknown = sorted(set(named) - known)
    return [
        require(
            "urdf.blocks",
            len(written) == len(recorded) and all(same),
            f"{sum(same)} of {len(recorded)} carried blocks (gazebo, transmission, "
            "ros2_control) are in the URDF, in order, as robot.json records them",
        ),
        require(
            "urdf.blocks.names",
            not unknown,
            f"links or joints the carried blocks name but the URDF lacks: {unknown[:3]}"
            if unknown
            else f"the {len(set(named))} links and joints the carried blocks name are in the URDF",
        ),
    ]
