"""The URDF as ROS-side tools read it: yourdfpy parses, validates and agrees on FK."""

from __future__ import annotations

import logging

import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.check.mujoco_check import random_configs


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
    tool = kit.doc.get("tool_frame")
    if tool:
        names = [j["name"] for j in kit.joints]
        errors = []
        for q in random_configs(kit, 10, seed=1):
            urdf.update_cfg(dict(zip(names, q, strict=True)))
            T = urdf.get_transform(tool, kit.base_frame)
            errors.append(T[:3, 3] - kit.fk(q)[:3, 3])
        findings.append(
            compare(
                "fk.yourdfpy_vs_robot_json",
                f"{tool} at 10 random configurations",
                np.zeros((len(errors), 3)),
                errors,
                1e-6,
                "m",
            )
        )
    return findings
