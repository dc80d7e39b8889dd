"""robot.json: the kit page's robot.json table, one machine-readable file for every number."""

from __future__ import annotations

import math
from collections.abc import Iterable

from simkit import __version__
from simkit.derive.solids import CIRCULAR_SEGMENTS, SPHERE_SEGMENTS
from simkit.emit import mjcf_world
from simkit.emit.step import step_origin
from simkit.kitio import layout
from simkit.kitio.cache import library_versions
from simkit.kitio.jsonout import dumps
from simkit.model.robot import InertiaDecision, Joint, Link, Robot, SimReports
from simkit.spec import urdf_blocks

LIBRARIES = ("numpy", "manifold3d", "trimesh", "coacd", "mujoco", "usd-core", "cadquery-ocp")


def _libraries() -> dict[str, str | None]:
    """`LIBRARIES`' versions; "cadquery-ocp" is OCP's, from cadquery-ocp-novtk (the same OCP
    without VTK, the dependency) when cadquery-ocp itself is not installed."""
    versions = library_versions((*LIBRARIES, "cadquery-ocp-novtk"))
    novtk = versions.pop("cadquery-ocp-novtk")
    versions["cadquery-ocp"] = versions["cadquery-ocp"] or novtk
    return versions


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
        out["inertia_decision"] = _decision(link.inertia_decision)
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


def document(robot: Robot, reports: SimReports) -> dict:
    """The robot.json content as plain data: the one place that decides its keys and their
    order, from the model, the derive products and the simulate stage's reports."""
    products = robot.products
    published = robot.published
    poses = {name: list(q) for name, q in robot.poses}
    geometric = products.reach_geometric
    doc: dict = {
        "name": robot.name,
        "title": robot.title,
        "description": robot.description,
        "units": {"length": "m", "mass": "kg", "angle": "rad", "time": "s", "torque": "N m"},
        "files": document_files(robot),
        "base_frame": products.base_frame or robot.root,
        "tool_frame": robot.tool_frame,
        "wrist_centre": robot.wrist_centre,
        "joints": [_joint(j, products.joint_motion.get(j.name)) for j in robot.movable_joints],
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
        "fk_reference": products.fk_reference,
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
            f"(manifold3d, {_segments(robot)} per circle); motors and gearboxes are "
            "plain envelopes",
            "mass_properties": "CoM and inertia of the solid at uniform density scaled to the "
            "link mass, unless the spec gives them",
            "collision": products.geometry_collision,
            "links": products.geometry_links,
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
            "libraries": _libraries(),
            "seeds": {"spec": robot.seed, **products.seeds},
            "sources": list(robot.sources),
            "published_estimated": list(robot.published_estimated),
        },
    }
    if reports.self_collision is not None:
        doc["geometry"]["self_collision"] = reports.self_collision
    _generalise(robot, doc)
    doc.update(_products(robot, reports))
    if (doc.get("gpu_scene") or {}).get("file", "") is None:  # no GPU scene: one line says why
        doc["files"].pop("mjcf_mjx")
    return doc


def _products(robot: Robot, reports: SimReports) -> dict:
    """The top-level entries that derive steps and the simulate stage produce, in a fixed
    order; absent products leave their key out."""
    p = robot.products
    out = {
        "ros2_control": p.ros2_control,
        "urdf_blocks": [urdf_blocks.summary(b) for b in robot.urdf_blocks] or None,
        "collision_pairs": p.collision_pairs,
        "gpu_scene": gpu_scene(robot),
        "ik_reference": p.ik_reference,
        "motion": p.motion,
        "benchmarks": _benchmarks(robot, reports),
        "validation": {"freefall": reports.freefall["record"]} if reports.freefall else None,
    }
    return {key: value for key, value in out.items() if value is not None}


def gpu_scene(robot: Robot) -> dict | None:
    """robot.json `gpu_scene`: the GPU scene's file, contact budget and sizes (the plan's
    colliders stay in the file itself), or the one line saying why the kit has none."""
    plan = robot.products.gpu_scene
    if plan is None:
        return None
    if "none" in plan:
        return {"file": None, "note": plan["none"]}
    out = {
        "file": layout.mjcf_mjx(robot.name),
        "contact_slots": plan["contact_slots"],
        "pair_slots": plan["pair_slots"],
        "pairs": len(plan["pairs"]) + len(plan["floor_pairs"]),  # explicit pairs, floor ones too
        "floor_pairs": plan["floor_pairs"],
        "nconmax": plan["nconmax"],
        "njmax": plan["njmax"],
        "solver": {"iterations": plan["iterations"], "ls_iterations": plan["ls_iterations"]},
        "method": plan["method"],
        "seed": plan["seed"],
        "samples": plan["samples"],
    }
    if "hold" in plan:
        out["solver"]["hold_error_m"] = plan["hold"]
    if plan.get("max_geom_pairs") is not None:
        out["max_geom_pairs"] = plan["max_geom_pairs"]
        out["broadphase_rank"] = plan["broadphase_rank"]
        if plan.get("broadphase_draws"):
            out["broadphase_draws"] = plan["broadphase_draws"]
    if "note" in plan:
        out["note"] = plan["note"]
    return out


def _benchmarks(robot: Robot, reports: SimReports) -> dict | None:
    """`benchmarks` with the simulate stage's inverse dynamics on the kit's MJCF filled in."""
    block, torques = robot.products.benchmarks, reports.benchmark_torques
    if block is None or torques is None:
        return block
    return {
        **block,  # keeps its key order: the two entries below replace placeholders
        "kit_model_check": {
            **torques["cycle_1kg"],
            "trajectory": layout.benchmark(robot.name, "csv"),
        },
        "rated_cycle_torque": {
            **torques["cycle_rated"],
            "note": "the same inverse dynamics for the rated-payload cycle, which has no "
            "trajectory file; the 80 % rule at the cycle poses does not bound the coupling "
            "between joints, so a fraction may exceed 1",
        },
    }


def _generalise(robot: Robot, doc: dict) -> None:
    """Drop the arm-only entries where they do not apply (no wrist centre or tool frame, no
    payload or repeatability published) and add a floating base, the MJCF scene file and the
    MJCF sensors where the spec has them. Arm kits are unchanged."""
    if not (robot.wrist_centre or robot.tool_frame):
        doc.pop("fk_reference")
        if not robot.products.reach_geometric and not doc["reach"]["published"]["wrist"]:
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
        if robot.needs_active_balance:  # the legged check holds it suspended (check/legged.py)
            doc["floating_base"]["needs_active_balance"] = robot.needs_active_balance
        doc["frames"][robot.root]["role"] = "the world; the floating base moves freely in it"
    if robot.mjcf is not None and robot.mjcf.sensors:
        doc["sensors"] = [s.model_dump(exclude_none=True) for s in robot.mjcf.sensors]
    if robot.loops:  # closed by the MJCF's welds and the USD's excluded joints (check/loops.py)
        doc["loops"] = [
            {"name": lp.name, "type": lp.type, "link1": lp.link1, "link2": lp.link2}
            | {"origin_xyz": list(lp.xyz), "origin_rpy": list(lp.rpy)}
            for lp in robot.loops
        ]


def _segments(robot: Robot) -> str:
    """How finely the meshes are tessellated, in words (spheres only where the robot has one,
    so a kit without spheres reads as before)."""
    text = f"{CIRCULAR_SEGMENTS} segments"
    if any(s.kind == "sphere" for link in robot.links for s in link.shapes):
        text += f" ({SPHERE_SEGMENTS} for spheres)"
    return text


def step_geometry(robot: Robot) -> dict:
    """robot.json `geometry.step`: where the STEP assembly is and how it relates to the
    meshes; `left_out` (only where there are some): links with no valid STEP solid."""
    out = {
        "file": layout.step(robot.name),
        "format": "ISO 10303-21, AP214 (AUTOMOTIVE_DESIGN), millimetres",
        "origin": step_origin(robot),
        "pose": "zero pose: every joint at 0 (a floating base at its start pose)",
        "relation": "the same primitives as the visual meshes, as exact B-rep solids (true "
        "cylinders, cones and spheres; Open CASCADE): one product per link, named as the link, "
        "placed at the zero pose; the meshes are those solids tessellated with "
        f"{_segments(robot)} per circle, so they hold a little less volume (under "
        "1 %); a link from a mesh file is the sewn faceted mesh",
    }
    if robot.products.step_left_out:
        out["left_out"] = [dict(entry) for entry in robot.products.step_left_out]
    return out


def _more_formats(robot: str) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """`files` keys beyond the MuJoCo, URDF and GLB entries, each with the paths that can
    stand for it (the first the kit holds is listed)."""
    return (
        ("sdf", (layout.sdf(robot),)),
        ("srdf", (layout.srdf(robot),)),
        ("usd", (layout.usd(robot), layout.usd(robot, binary=True))),
        ("usd_asset", (layout.usd_asset(robot), layout.usd_asset(robot, binary=True))),
        ("step", (layout.step(robot),)),
    )


def files_block(robot: Robot, kit_files: Iterable[str]) -> dict[str, str]:
    """robot.json `files`: the entry file of every format the kit holds, so a reader finds
    each one without knowing the layout (issue 38)."""
    have = set(kit_files)
    files = dict(document_files(robot))
    if (gpu_scene(robot) or {}).get("file", "") is None:  # no GPU scene written: not listed
        files.pop("mjcf_mjx")
    for key, candidates in _more_formats(robot.name):
        found = next((path for path in candidates if path in have), None)
        if found is not None:
            files[key] = found
    return files


def document_files(robot: Robot) -> dict[str, str]:
    """The `files` entries every kit has (the MJCF scene where the servos are apart)."""
    files = {
        "urdf": layout.urdf(robot.name),
        "mjcf": layout.mjcf(robot.name),
        "mjcf_mjx": layout.mjcf_mjx(robot.name),
        "glb": layout.glb(robot.name),
    }
    if not mjcf_world.servos_in_main(robot):
        files["mjcf_scene"] = layout.mjcf_scene(robot.name)
    return files


def emit(
    robot: Robot, reports: SimReports, step: bool = True, kit_files: Iterable[str] = ()
) -> dict[str, bytes]:
    """`robot.json` (a report emitter: it runs after the simulate stage); `step`: the kit has
    a STEP assembly (`geometry.step`, else null); `kit_files`: the model emitters' paths,
    whose formats `files` lists."""
    doc = document(robot, reports)
    doc["files"] = files_block(robot, kit_files)
    doc["geometry"]["step"] = step_geometry(robot) if step else None
    if robot.source is not None:  # an imported robot; a hand-written spec adds nothing
        doc["source"] = {"file": robot.source[0], "sha256": robot.source[1]}
        if robot.source_assets:
            doc["source"]["assets"] = dict(robot.source_assets)
        for key, value in robot.source_about:  # format, original, args (model/resolve.py)
            doc["source"][key] = dict(value) if key == "args" else value
        doc["source_differences"] = [
            {"what": what, "reason": reason, **({"kit": kit} if kit is not None else {})}
            for what, reason, kit in robot.source_differences
        ]
    return {layout.ROBOT_JSON: dumps(doc)}


def _decision(decision: InertiaDecision) -> dict:
    """The decision as robot.json writes it next to the link."""
    keys = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
    return {
        "action": decision.action,
        "reason": decision.reason,
        "problem": decision.problem,
        "reported": dict(zip(keys, decision.reported, strict=True)),
        "emitted": dict(zip(keys, decision.emitted, strict=True)) if decision.emitted else None,
        "rule": "emitted = every principal moment set to their mean (MuJoCo balanceinertia); "
        "mass and CoM as reported",
    }
