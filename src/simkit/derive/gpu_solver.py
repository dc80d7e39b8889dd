"""The GPU scene's solver settings, per robot (issue 41): the fewest solver and line-search
iterations for which the robot, held by its servos at each named pose, ends where it does with
every contact and MuJoCo's default solver.

Why per robot: fewer iterations step faster on a GPU (Asimov's scene ran 1.48x faster at 1 / 4
than at 4 / 8 on an H200), but one fixed low setting broke robots simkit had never seen (an
imported quadruped ended its stance 82 mm away at 2 / 4). So each candidate of `CANDIDATES`,
cheapest first, is simulated in C MuJoCo for `HOLD_SECONDS` from every named pose, and the
first whose bodies all end within `HOLD_MARGIN` of the reference's is written. A candidate
must also allow the iterations MuJoCo's solver takes to converge in those holds (it stops
earlier by its tolerance): an unconverged step depends on the implementation's line search,
and at 1 / 1 Asimov's scene in MJX (float32) ended 13 mm from C MuJoCo's after 100 steps from
a perturbed keyframe; at 3 / 6, where it converges, within 1.3e-5.

The model is the derive's own (no emitter, no check): the robot's bodies, inertials, joints
(armature, damping, friction loss, springs, limits), mimic equalities and position servos as
the kit's MJCF writes them, with the GPU scene's colliders. The reference collides every
collider pair the main MJCF collides (and every collider with the floor) at MuJoCo's default
solver (100 / 50, the main MJCF's); a candidate collides only the plan's explicit pairs.
`HOLD_MARGIN` is half the `gpu_scene` check's 5 mm, which then proves the written files
against each other.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from simkit.derive.gpu_colliders import never_collided, scratch_geom
from simkit.model.kinematics import quat_wxyz, rpy_matrix
from simkit.model.robot import Joint, Robot

#: (iterations, ls_iterations), cheapest first, line search at twice the iterations (the
#: ratio of the 4 / 8 every kit had before)
CANDIDATES = ((1, 2), (2, 4), (3, 6), (4, 8), (6, 12), (8, 16), (16, 32))
HOLD_SECONDS = 2.0
#: m: the `gpu_scene` check's tolerance (check/gpu_scene.py; derive never imports a check):
#: beyond it even at the closest candidate, the kit has no GPU scene and says why
HOLD_TOLERANCE = 0.005
#: m: how far a candidate's bodies may end from the reference's: half the check's tolerance,
#: the rest left to what the derive's model does not share with the files (mesh hulls)
HOLD_MARGIN = HOLD_TOLERANCE / 2
#: the kit MJCF's defaults (emit/mjcf.py): timestep (s) and the mimic equalities' solver
TIMESTEP = 0.002
MIMIC_TIMECONST_STEPS = 2.0
MIMIC_SOLIMP = (0.95, 0.99, 0.001)
FLOOR = "floor"


def _text(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def _joint(body: ET.Element, joint: Joint) -> None:
    if joint.type == "floating":
        ET.SubElement(body, "freejoint", name=joint.name)
        return
    if not joint.movable:
        return
    attrs = {
        "name": joint.name,
        "type": "slide" if joint.type == "prismatic" else "hinge",
        "axis": _text(joint.axis),
        "armature": repr(float(joint.armature)),
        "damping": repr(float(joint.damping)),
        "frictionloss": repr(float(joint.friction)),
    }
    if joint.type != "continuous" and joint.lower is not None:
        attrs["range"] = _text((joint.lower, joint.upper))
    if joint.stiffness:
        attrs.update(stiffness=repr(float(joint.stiffness)), springref=repr(joint.springref))
    if joint.solreflimit is not None:
        attrs["solreflimit"] = _text(joint.solreflimit)
    if joint.solimplimit is not None:
        attrs["solimplimit"] = _text(joint.solimplimit)
    if joint.margin:
        attrs["margin"] = repr(float(joint.margin))
    ET.SubElement(body, "joint", attrs)


def _bodies(robot: Robot, root: ET.Element, asset: ET.Element, geoms: list[dict]) -> None:
    bodies = {robot.root: ET.SubElement(root, "worldbody")}
    if robot.floating_joint is not None:  # a floating base stands on the floor
        ET.SubElement(bodies[robot.root], "geom", name=FLOOR, type="plane", size="0 0 1")
    by_link: dict[str, list[dict]] = {}
    for geom in geoms:
        by_link.setdefault(geom["link"], []).append(geom)
    for joint in robot.joints:
        quat = quat_wxyz(rpy_matrix(joint.rpy))
        attrs = {"name": joint.child, "pos": _text(joint.xyz), "quat": _text(quat)}
        body = bodies[joint.child] = ET.SubElement(bodies[joint.parent], "body", attrs)
        link = robot.link(joint.child)
        if link.inertial is not None:
            ixx, iyy, izz, ixy, ixz, iyz = link.inertial.inertia
            ET.SubElement(
                body,
                "inertial",
                pos=_text(link.inertial.com),
                mass=repr(float(link.inertial.mass)),
                fullinertia=_text((ixx, iyy, izz, ixy, ixz, iyz)),
            )
        _joint(body, joint)
        for geom in by_link.get(joint.child, []):
            scratch_geom(robot, asset, body, geom, own_cap=True)


def _tail(robot: Robot, root: ET.Element, timestep: float) -> None:
    """Loop welds, mimic equalities and position servos as the kit's MJCF writes them."""
    mimics = [j for j in robot.joints if j.mimic is not None]
    if mimics or robot.loops:
        equality = ET.SubElement(root, "equality")
        for loop in robot.loops:  # as emit/mjcf.py weld_attributes writes them
            body1, body2 = ("world" if n == robot.root else n for n in (loop.link1, loop.link2))
            relpose = (*loop.xyz, *quat_wxyz(rpy_matrix(loop.rpy)))
            ET.SubElement(
                equality,
                "weld",
                body1=body1,
                body2=body2,
                relpose=_text(relpose),
                solref=_text((MIMIC_TIMECONST_STEPS * timestep, 1.0)),
                solimp=_text(MIMIC_SOLIMP),
            )
        for joint in mimics:
            leader, multiplier, offset = joint.mimic  # type: ignore[misc]
            ET.SubElement(
                equality,
                "joint",
                joint1=joint.name,
                joint2=leader,
                polycoef=_text((offset, multiplier, 0, 0, 0)),
                solref=_text((MIMIC_TIMECONST_STEPS * timestep, 1.0)),
                solimp=_text(MIMIC_SOLIMP),
            )
    if robot.actuators:
        actuator = ET.SubElement(root, "actuator")
        for act in robot.actuators:
            joint = robot.joint(act.joint)
            attrs = {"joint": act.joint, "kp": repr(act.kp), "kv": repr(act.kv)}
            if joint.lower is not None and joint.type != "continuous":
                attrs["ctrlrange"] = _text((joint.lower, joint.upper))
            attrs["forcerange"] = _text((-act.forcerange, act.forcerange))
            ET.SubElement(actuator, "position", attrs)


def hold_xml(robot: Robot, plan: dict, solver: tuple[int, int] | None) -> str:
    """The robot with the plan's colliders: with `solver` (iterations, ls_iterations), only
    the plan's explicit pairs collide; without, every pair the main MJCF collides does, at
    MuJoCo's default solver."""
    timestep = robot.mjcf.timestep if robot.mjcf is not None else TIMESTEP
    root = ET.Element("mujoco", model=f"{robot.name}_gpu_hold")
    ET.SubElement(root, "compiler", angle="radian", autolimits="true", inertiafromgeom="false")
    option = {"timestep": repr(timestep), "integrator": "implicitfast"}
    if solver is not None:
        option.update(iterations=str(solver[0]), ls_iterations=str(solver[1]))
    ET.SubElement(root, "option", option)
    asset = ET.SubElement(root, "asset")
    boxes = [g for g in plan["colliders"] if "box_for" in g]
    stand_ins = [{**g, "name": f"{g['name']}_box", "kind": "box", "size": _box(g)} for g in boxes]
    geoms = plan["colliders"] + (stand_ins if solver is not None else [])
    _bodies(robot, root, asset, geoms)
    _tail(robot, root, timestep)
    default = ET.Element("default")
    off = {"contype": "0", "conaffinity": "0"} if solver is not None else {}
    ET.SubElement(default, "geom", off)
    root.insert(1, default)
    contact = ET.SubElement(root, "contact")
    if solver is None:
        for a, b in sorted(never_collided(robot)):
            ET.SubElement(contact, "exclude", body1=a, body2=b)
        return ET.tostring(root, encoding="unicode")
    swaps = {g["name"]: set(g["box_for"]) for g in boxes}
    for a, b in plan["pairs"]:
        one = f"{a}_box" if b in swaps.get(a, ()) else a
        two = f"{b}_box" if a in swaps.get(b, ()) else b
        ET.SubElement(contact, "pair", geom1=one, geom2=two)
    for geom in plan["floor_pairs"]:
        ET.SubElement(contact, "pair", geom1=FLOOR, geom2=geom)
    return ET.tostring(root, encoding="unicode")


def _box(geom: dict) -> list[float]:
    """A cylinder's stand-in box's full size (m), as the GPU scene writes it."""
    side = 2 * geom["box_half"]
    return [side, side, geom["length"]]


def _starts(robot: Robot) -> list[tuple[np.ndarray, np.ndarray]]:
    """(qpos, ctrl) at each named pose (zeros without any), a floating base at its origin."""
    names = [j.name for j in robot.movable_joints]
    poses = [q for _, q in robot.poses] or [tuple(0.0 for _ in names)]
    floating = robot.floating_joint
    base = [*floating.xyz, *quat_wxyz(rpy_matrix(floating.rpy))] if floating else []
    out = []
    for q in poses:
        values = dict(zip(names, q, strict=True))
        ctrl = [values[a.joint] for a in robot.actuators]
        out.append((np.array([*base, *q], dtype=float), np.array(ctrl, dtype=float)))
    return out


def _held(xml: str, starts: list) -> tuple[list[np.ndarray], int]:
    """Body positions (world, m) after `HOLD_SECONDS` from each start, and the most solver
    iterations one step took."""
    import mujoco

    model = mujoco.MjModel.from_xml_string(xml)
    out, most = [], 0
    for qpos, ctrl in starts:
        data = mujoco.MjData(model)
        data.qpos[:], data.ctrl[:] = qpos, ctrl
        for _ in range(round(HOLD_SECONDS / model.opt.timestep)):
            mujoco.mj_step(model, data)
            most = max(most, int(data.solver_niter[0]))
        out.append(data.xpos.copy())
    return out, most


def converged_iterations(robot: Robot, plan: dict) -> int:
    """The most iterations MuJoCo's solver takes in one step of the holds with every contact
    at its defaults (it stops earlier where it converges)."""
    return _held(hold_xml(robot, plan, None), _starts(robot))[1]


def hold_errors(robot: Robot, plan: dict, candidates) -> list[float]:
    """For each (iterations, ls_iterations) of `candidates`: the largest distance (m) a body
    ends from where the reference holds it, over the named poses."""
    starts = _starts(robot)
    reference = _held(hold_xml(robot, plan, None), starts)[0]
    out = []
    for solver in candidates:
        held = _held(hold_xml(robot, plan, solver), starts)[0]
        pairs = zip(held, reference, strict=True)
        out.append(max(float(np.linalg.norm(a - b, axis=1).max()) for a, b in pairs))
    return out


def fewest_iterations(robot: Robot, plan: dict) -> tuple[tuple[int, int], float]:
    """((iterations, ls_iterations), the largest distance (m) a body ends from the
    reference's) of the cheapest of `CANDIDATES` with at least the iterations the solver
    takes to converge (`converged_iterations`) and within `HOLD_MARGIN`, else of the closest."""
    least = converged_iterations(robot, plan)
    best: tuple[float, tuple[int, int]] | None = None
    for solver in (c for c in CANDIDATES if c[0] >= least):  # most robots hold at the first
        (error,) = hold_errors(robot, plan, [solver])
        if error <= HOLD_MARGIN:
            return solver, error
        best = min(best or (error, solver), (error, solver))
    if best is None:  # the solver needs more than every candidate: the largest
        return CANDIDATES[-1], hold_errors(robot, plan, CANDIDATES[-1:])[0]
    return best[1], best[0]
