"""Reading the USD source with usd-core's own UsdPhysics parser (`LoadUsdPhysicsFromRange`),
not the importer's reader: the composed stage (with the import's variant) as a `Robot` of
bodies (MassAPI mass kg, CoM m and inertia kg m^2 in the body frame) and joints (kind, the
two bodies, their local frames in m, axis, limits in rad or m, effort in N m or N), its root
body and the breadth-first tree, and `Robot.poses` (each body relative to the root body at
joint values).

Frames: the kit's link frame of a body is its body frame moved (not turned) to the joint
frame on it (importer/formats/usd/tree.py); `source_robot` finds that frame from the parser's
joints with the same breadth-first walk. Kept apart from the comparison (the package's
`__init__.py`) because it is the one place that speaks pxr, imported lazily per function.
Bodies and joints are named as the import names them (`unique_names`): a naming convention
the kit must match, not part of the proof.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simkit.check.source.usd import dynamics
from simkit.importer.formats.usd.stage import unique_names


@dataclass
class Body:
    """A source body: its MassAPI values (kg, m and kg m^2 in the body frame; None where not
    authored) and the kit's link frame in its body frame (`frame`)."""

    mass: float | None = None
    com: np.ndarray | None = None
    inertia: np.ndarray | None = None
    frame: np.ndarray = field(default_factory=lambda: np.eye(4))


@dataclass
class Joint:
    """A source joint from the parser: kind, bodies (names), frames (m), axis, limits."""

    kind: str
    body0: str | None
    body1: str | None
    pose0: np.ndarray
    pose1: np.ndarray
    axis: int = 0
    limits: tuple[float, float] | None = None
    #: N m or N: `simkit:effortLimit` where authored, else the drive's force limit
    effort: float | None = None
    #: {damping, friction, armature} where the source gives them (SI; dynamics.py)
    dynamics: dict[str, float] = field(default_factory=dict)
    #: the joint's place in the stage's order (as authored: the order of a chain's joints)
    order: int = 0


@dataclass
class Robot:
    """The source's bodies and joints by unique prim name, its root body and tree."""

    bodies: dict[str, Body] = field(default_factory=dict)
    joints: dict[str, Joint] = field(default_factory=dict)
    root: str = ""
    #: (joint name, flipped) in breadth-first order from the root
    tree: list[tuple[str, bool]] = field(default_factory=list)
    #: further root bodies bolted to the world -> their pose relative to the root body
    bolted: dict[str, np.ndarray] = field(default_factory=dict)
    #: tree joint -> the further joints between the same two bodies (a multi-DOF body)
    chains: dict[str, list[str]] = field(default_factory=dict)

    def poses(self, q: dict[str, float]) -> dict[str, np.ndarray]:
        """Each body's pose relative to the root body at joint values `q` (rad or m; a
        spherical joint J from J_x, J_y, J)."""
        out = {self.root: np.eye(4), **self.bolted}
        for name, flip in self.tree:
            j = self.joints[name]
            motion = _motion(j, name, q)
            if flip:
                out[j.body0] = out[j.body1] @ j.pose1 @ np.linalg.inv(motion) @ _inv(j.pose0)
            else:
                out[j.body1] = out[j.body0] @ j.pose0 @ motion @ _inv(j.pose1)
                for more in self.chains.get(name, []):
                    k = self.joints[more]
                    out[j.body1] = out[j.body1] @ k.pose1 @ _motion(k, more, q) @ _inv(k.pose1)
        return out


def _motion(j: Joint, name: str, q: dict[str, float]) -> np.ndarray:
    out = np.eye(4)
    if j.kind in ("revolute", "prismatic"):
        value = q.get(name, 0.0)
        if j.kind == "prismatic":
            out[j.axis, 3] = value
        else:
            out[:3, :3] = _turn(j.axis, value)
    elif j.kind == "spherical":
        parts = [q.get(f"{name}_x", 0.0), q.get(f"{name}_y", 0.0), q.get(name, 0.0)]
        out[:3, :3] = _turn(0, parts[0]) @ _turn(1, parts[1]) @ _turn(2, parts[2])
    return out


def _turn(axis: int, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    i, k = [(1, 2), (2, 0), (0, 1)][axis]
    out = np.eye(3)
    out[i, i], out[i, k], out[k, i], out[k, k] = c, -s, s, c
    return out


def _inv(t: np.ndarray) -> np.ndarray:
    return np.linalg.inv(t)


def _pose(position, orientation, meters: float) -> np.ndarray:
    out = np.eye(4)
    w, (x, y, z) = float(orientation.GetReal()), orientation.GetImaginary()
    out[:3, :3] = _quat(w, float(x), float(y), float(z))
    out[:3, 3] = np.asarray(position, dtype=float) * meters
    return out


def _quat(w: float, x: float, y: float, z: float) -> np.ndarray:
    n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def source_robot(path: Path, variant: str | None) -> Robot:
    """The composed stage's robot as usd-core's UsdPhysics parser describes it."""
    from pxr import Usd, UsdGeom, UsdPhysics

    stage = Usd.Stage.Open(str(path), Usd.Stage.LoadAll)
    if variant:
        with Usd.EditContext(stage, stage.GetSessionLayer()):
            for prim in stage.Traverse():
                sets = prim.GetVariantSets()
                if sets.HasVariantSet("Physics"):
                    sets.GetVariantSet("Physics").SetVariantSelection(variant)
    meters = float(UsdGeom.GetStageMetersPerUnit(stage)) or 1.0
    kilograms = float(UsdPhysics.GetStageKilogramsPerUnit(stage)) or 1.0
    load = getattr(UsdPhysics, "UsdPhysicsLoadStageFromPrimRange", None)
    parsed = (load or UsdPhysics.LoadUsdPhysicsFromRange)(stage, ["/"])
    kinds = {
        UsdPhysics.ObjectType.RevoluteJoint: "revolute",
        UsdPhysics.ObjectType.PrismaticJoint: "prismatic",
        UsdPhysics.ObjectType.FixedJoint: "fixed",
        UsdPhysics.ObjectType.SphericalJoint: "spherical",
    }
    body_paths = [str(p) for p in parsed.get(UsdPhysics.ObjectType.RigidBody, ([], []))[0]]
    names = unique_names(stage, body_paths)
    joints, joint_paths = [], []
    for kind, label in kinds.items():
        for at, desc in zip(*parsed.get(kind, ([], [])), strict=True):
            joints.append((str(at), label, desc))
            joint_paths.append(str(at))
    joint_names = unique_names(stage, joint_paths)
    every = Usd.PrimRange(stage.GetPseudoRoot(), Usd.TraverseInstanceProxies())
    authored = {str(p.GetPath()): i for i, p in enumerate(every)}
    robot = Robot()
    more = None
    for at, label, d in sorted(joints):
        b0, b1 = str(d.body0), str(d.body1)
        joint = Joint(
            label, names.get(b0), names.get(b1),
            _pose(d.localPose0Position, d.localPose0Orientation, meters),
            _pose(d.localPose1Position, d.localPose1Orientation, meters),
        )  # fmt: skip
        if label in ("revolute", "prismatic"):
            joint.axis = "XYZ".index(str(d.axis).rsplit(".", 1)[-1][-1])
            joint.limits = _limits_of(d.limit, label, meters)
            lever = meters if label == "revolute" else 1.0
            joint.effort = _effort_of(stage.GetPrimAtPath(at), d.drive, kilograms * meters * lever)
            more = dynamics.others(stage, variant) if more is None else more
            prim = stage.GetPrimAtPath(at)
            joint.dynamics = dynamics.of_joint(prim, label, kilograms, meters, more)
        joint.order = authored.get(at, 0)
        if not d.excludeFromArticulation:
            robot.joints[joint_names[at]] = joint
    for at, name in names.items():
        robot.bodies[name] = _mass_of(stage.GetPrimAtPath(at), meters, kilograms)
    _walk(robot, stage, names)
    return robot


def _limits_of(limit, label: str, meters: float) -> tuple[float, float] | None:
    if not limit.enabled or not all(abs(v) < 1e30 for v in (limit.lower, limit.upper)):
        return None
    scale = math.radians(1.0) if label == "revolute" else meters
    low, high = (float(str(np.float32(v))) * scale for v in (limit.lower, limit.upper))
    return low, high


def _effort_of(prim, drive, unit: float) -> float | None:
    """The joint's effort limit (N m or N; `unit` the stage's force or torque unit in SI): the
    kit's own `simkit:effortLimit` where authored (0: none), else the parser's drive force
    limit; None where neither is finite and positive."""
    from simkit.emit.usd.physics import EFFORT_LIMIT

    attr = prim.GetAttribute(EFFORT_LIMIT) if prim else None
    value = attr.Get() if attr else None
    if value is None and drive is not None and drive.enabled:
        value = drive.forceLimit
    if value is None or not 0 < float(value) < 1e30:
        return None
    return float(str(np.float32(value))) * unit


def _mass_of(prim, meters: float, kilograms: float) -> Body:
    """The body's authored MassAPI values (body frame)."""
    from pxr import UsdPhysics

    body = Body()
    if not prim.HasAPI(UsdPhysics.MassAPI):
        return body
    api = UsdPhysics.MassAPI(prim)
    mass = api.GetMassAttr()
    if mass.HasAuthoredValue() and mass.Get() > 0:
        body.mass = float(str(np.float32(mass.Get()))) * kilograms
    com = api.GetCenterOfMassAttr()
    if com.HasAuthoredValue() and all(v > -1e30 for v in com.Get()):
        body.com = np.array([float(str(np.float32(v))) for v in com.Get()]) * meters
    diagonal, axes = api.GetDiagonalInertiaAttr(), api.GetPrincipalAxesAttr()
    if diagonal.HasAuthoredValue() and any(v > 0 for v in diagonal.Get()):
        moments = np.diag([float(str(np.float32(v))) for v in diagonal.Get()])
        turn = np.eye(3)
        if axes.HasAuthoredValue():
            q = axes.Get()
            turn = _quat(float(q.GetReal()), *(float(v) for v in q.GetImaginary()))
        body.inertia = turn @ moments @ turn.T * kilograms * meters * meters
    if diagonal.HasAuthoredValue() and body.com is None and body.mass is not None:
        body.com = np.zeros(3)  # inertia written about a CoM left unwritten: the body origin
    return body


def _walk(robot: Robot, stage, names: dict[str, str]) -> None:
    """The root body (the articulation root, a world joint's body, else the first body no
    joint hangs from) and the breadth-first tree; each body's link frame."""
    from pxr import UsdPhysics

    bodies = set(names.values())
    roots = [p for p in stage.Traverse() if p.HasAPI(UsdPhysics.ArticulationRootAPI)]
    root = names.get(str(roots[0].GetPath())) if roots else None
    inner, claimed = {}, {}
    for n, j in sorted(robot.joints.items(), key=lambda item: item[1].order):
        if not (j.body0 in bodies and j.body1 in bodies):
            continue
        first = claimed.get(j.body1)
        if first is None:
            claimed[j.body1] = n
            inner[n] = j
        elif robot.joints[first].body0 == j.body0:  # one more DOF between the same bodies
            robot.chains.setdefault(first, []).append(n)
        # else: a body's second parent joint closes a loop: not in the tree
    world = [
        (n, j)
        for n, j in sorted(robot.joints.items())
        if (j.body0 in bodies) != (j.body1 in bodies)
    ]
    for _, j in world:
        if root is None and (j.body0 in bodies) != (j.body1 in bodies):
            root = j.body1 if j.body1 in bodies else j.body0
    if root is None:
        children = {j.body1 for j in inner.values()}
        root = next(n for n in sorted(bodies) if n not in children and _touches(n, inner))
    held = [j for _, j in sorted(world, key=lambda item: item[1].order) if root == j.body1]
    if held:  # the last of the joints holding the root to the world (a chain), as imported
        robot.bodies[root].frame = _moved(held[-1].pose1)
    else:
        for _, j in world:
            if root == j.body0:
                robot.bodies[root].frame = _moved(j.pose0)
                break
    robot.root, todo, seen = root, [root], {root}
    if held and held[0].kind == "fixed":  # further articulations bolted to the world alike
        base = held[0].pose0 @ _inv(held[0].pose1)
        for _, j in world:
            if j.kind == "fixed" and j.body1 in bodies and j.body1 not in {*claimed, root}:
                robot.bodies[j.body1].frame = _moved(j.pose1)
                robot.bolted[j.body1] = _inv(base) @ j.pose0 @ _inv(j.pose1)
                seen.add(j.body1)
                todo.append(j.body1)
    while todo:
        at = todo.pop(0)
        for name, j in sorted(inner.items()):
            if at not in (j.body0, j.body1) or any(name == t for t, _ in robot.tree):
                continue
            flip = j.body1 == at
            other = j.body0 if flip else j.body1
            if other in seen:
                continue
            seen.add(other)
            last = robot.joints[robot.chains[name][-1]] if name in robot.chains and not flip else j
            robot.bodies[other].frame = _moved(j.pose0 if flip else last.pose1)
            robot.tree.append((name, flip))
            todo.append(other)


def _moved(pose: np.ndarray) -> np.ndarray:
    """The kit's link frame of a body whose joint frame is `pose`: moved there, not turned."""
    out = np.eye(4)
    out[:3, 3] = pose[:3, 3]
    return out


def _touches(name: str, joints: dict) -> bool:
    return any(name in (j.body0, j.body1) for j in joints.values())
