"""The kit is the USD robot it was imported from: the kept layers are laid out again, the
stage composed (with the variant the import read, robot.json `source.args.variant`) and
parsed by usd-core's own UsdPhysics parser (`LoadUsdPhysicsFromRange`: bodies, joints, their
frames, axes and limits), not the importer's reader; the kit's URDF is read by yourdfpy.
Compared, under the source's prim names (made unique in path order, renames from robot.json):

- joint types (revolute, continuous for an unbounded revolute, prismatic, fixed; a
  spherical joint as the kit's three revolute joints J_x, J_y, J) and limits (degrees to rad);
- every body's MassAPI mass (kg, <= 1e-6 relative), CoM and inertia in the body frame;
- the pose of every body relative to the root body at 100 seeded configurations (1e-6 m,
  1e-6 in rotation): the source's composed from the parser's joint frames
  (body1 = body0 * localPose0 * motion(q) * localPose1^-1), the kit's from its URDF.

Frames: the kit's link frame of a body is its body frame moved (not turned) to the joint
frame on it (importer/formats/usd/tree.py); this check finds that frame from the parser's joints and
the same breadth-first walk. A difference passes only where `source_differences` lists it.
"""

from __future__ import annotations

import hashlib
import math
import tempfile
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.check.source import kit_usd
from simkit.check.source.shared import ABS_LENGTH, REL, SHOWN, Allowed, inertia_close
from simkit.check.source.urdf import load_urdf
from simkit.kitio.oneline import one_line

SEEDS = 100
#: m and rotation-matrix entries: FK agreement
FK_TOL = 1e-6


def remake(path: Path, args: dict[str, str]) -> bytes:
    """The kept root layer made from the original: it is kept byte for byte."""
    return path.read_bytes()


def compare(kit: Kit, path: Path) -> list[Finding]:
    """Findings for the USD at `path` (its other layers beside it or kept in the kit)
    against the kit's URDF, differences allowed where robot.json lists them."""
    recorded = kit.doc.get("source") or {}
    if hashlib.sha256(path.read_bytes()).hexdigest() != recorded.get("sha256"):
        return []  # not the file the import read (source.digest fails): never composed
    variant = (recorded.get("args") or {}).get("variant")
    with tempfile.TemporaryDirectory(prefix="simkit-source-") as tmp:
        folder = Path(tmp)
        problems = _lay_out(path, recorded.get("assets") or {}, folder)
        if problems:
            return [require("source.digest", False, p) for p in problems[:SHOWN]]
        try:
            source = source_robot(folder / path.name, variant)
        except Exception as exc:  # pxr raises Tf errors on a stage it cannot compose
            why = " ".join(str(exc).split())[:200]
            return [require("source.read", False, f"usd-core cannot read the source: {why}")]
    try:
        built = load_urdf(kit.path(kit.urdf))
    except Exception as exc:
        why = " ".join(str(exc).split())[:200]
        return [require("source.read", False, f"yourdfpy cannot read the kit: {why}")]
    allowed = Allowed.of(kit.doc)
    out = _findings("source.joints", _joints(source, built, allowed), _said(source, "joints"))
    out += _findings("source.links", _bodies(source, built, allowed), _said(source, "links"))
    fk = _fk(source, built, allowed)
    out += _findings("source.fk", fk, f"every body's pose agrees at {SEEDS} configurations")
    return out + kit_usd.compare(kit, _for_kit_usd(source), allowed)


def _for_kit_usd(source: Robot) -> tuple[dict[str, float], dict[str, tuple]]:
    """The source's ({body: mass}, {joint: (kind, limits in deg or m)}) for kit_usd.py."""
    masses = {n: b.mass for n, b in source.bodies.items() if b.mass is not None}
    joints = {}
    for name, j in source.joints.items():
        if j.kind in ("revolute", "prismatic"):
            span = j.limits
            if span is not None and j.kind == "revolute":
                span = (math.degrees(span[0]), math.degrees(span[1]))
            joints[name] = (j.kind, span)
    return masses, joints


def _said(source: Robot, what: str) -> str:
    if what == "joints":
        return f"{len(source.joints)} joints: types and limits agree with the USD's physics parser"
    return f"{len(source.bodies)} bodies: MassAPI masses, CoMs and inertias agree"


def _lay_out(main: Path, assets: dict, folder: Path) -> list[str]:
    """The root layer and its recorded layers in `folder` as the import read them; problems:
    a layer missing, outside the folder, or not the recorded one."""
    (folder / main.name).write_bytes(main.read_bytes())
    kept = main.parent / (main.name.rsplit(".", 1)[0] + ".assets")
    problems = []
    for rel, digest in sorted(assets.items()):
        target = (folder / rel).resolve()
        if folder.resolve() not in target.parents or ".." in rel.split("/"):
            problems.append(f"layer '{rel}' lies outside the source's folder")
            continue
        for candidate in (main.parent / rel, kept / f"{digest}{PurePosixPath(rel).suffix.lower()}"):
            if candidate.is_file() and hashlib.sha256(candidate.read_bytes()).hexdigest() == digest:
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(candidate.read_bytes())
                break
        else:
            problems.append(f"layer '{rel}' is missing or not the one the import read")
    return problems


def _kit_name(table: dict[str, str], name: str) -> str:
    return table.get(one_line(name), name)


def _joints(source: Robot, built, allowed: Allowed) -> list[str]:
    """Each source joint in the kit: its type, and its limits (rad or m)."""
    kit = {j.name: j for j in built.joints}
    out = []
    for name, joint in sorted(source.joints.items()):
        key = f"joints.{name}"
        if key in allowed.keys:
            continue
        parts = (f"{name}_x", f"{name}_y", name) if joint.kind == "spherical" else (name,)
        found = [kit.get(_kit_name(allowed.joints, p)) for p in parts]
        if any(f is None for f in found):
            out.append(f"joint '{name}' is missing from the kit")
            continue
        want = _kit_type(joint)
        got = "spherical" if joint.kind == "spherical" else found[0].type
        if joint.kind == "spherical":
            got = "spherical" if all(f.type in ("revolute", "continuous") for f in found) else "?"
        if want != got and f"{key}.type" not in allowed.keys:
            out.append(f"joint '{name}': {want} in the USD, {got} in the kit")
        if want in ("revolute", "prismatic") and want == got:
            out += _limits(name, joint, found[0], allowed)
    return out


def _kit_type(joint) -> str:
    if joint.kind == "revolute" and joint.limits is None:
        return "continuous"
    return joint.kind


def _limits(name: str, joint, kit, allowed: Allowed) -> list[str]:
    out = []
    for i, attr in enumerate(("lower", "upper")):
        if f"joints.{name}.{attr}" in allowed.keys:
            continue
        want = joint.limits[i]
        got = None if kit.limit is None else getattr(kit.limit, attr)
        if got is None or abs(float(got) - want) > REL * abs(want) + ABS_LENGTH:
            out.append(f"joint '{name}': {attr} {want:.9g} in the USD, {got} in the kit")
    return out


def _bodies(source: Robot, built, allowed: Allowed) -> list[str]:
    """Each body's authored mass, CoM and inertia (body frame) against the kit's link."""
    kit = {link.name: link for link in built.links}
    out = []
    for name, body in sorted(source.bodies.items()):
        link = kit.get(_kit_name(allowed.links, name))
        key = f"links.{name}"
        if link is None:
            if key not in allowed.keys:
                out.append(f"link '{name}' is missing from the kit")
            continue
        if body.mass is None:
            continue
        inertial = link.inertial
        mass = 0.0 if inertial is None else float(inertial.mass or 0.0)
        if f"{key}.mass" not in allowed.keys and abs(mass - body.mass) > REL * body.mass:
            out.append(f"link '{name}': mass {body.mass:.9g} kg in the USD, {mass:.9g} in the kit")
        if inertial is None or inertial.origin is None:
            continue
        pose = body.frame @ np.asarray(inertial.origin, dtype=float)
        com = pose[:3, 3]
        far = None if body.com is None else np.max(np.abs(com - body.com))
        bound = 0.0 if body.com is None else REL * np.max(np.abs(body.com)) + ABS_LENGTH
        if far is not None and f"{key}.com" not in allowed.keys and far > bound:
            out.append(f"link '{name}': CoM {_v(body.com)} m in the USD, {_v(com)} in the kit")
        if body.inertia is not None and f"{key}.inertia" not in allowed.keys:
            tensor = pose[:3, :3] @ np.asarray(inertial.inertia) @ pose[:3, :3].T
            if not inertia_close(body.inertia, tensor):
                out.append(f"link '{name}': inertia (body axes) differs from the USD's")
    return out


def _fk(source: Robot, built, allowed: Allowed) -> list[str]:
    """Every body's pose relative to the root body at SEEDS seeded configurations."""
    rng = np.random.default_rng(0)
    movable = [j for j in built.joints if j.type in ("revolute", "continuous", "prismatic")]
    back = {v: k for k, v in allowed.joints.items()}
    names = {k: _kit_name(allowed.links, k) for k in source.bodies}
    out: list[str] = []
    for _ in range(SEEDS):
        q = {}
        for joint in movable:
            low, high = -math.pi, math.pi
            if joint.type != "continuous" and joint.limit is not None:
                low = -1.0 if joint.limit.lower is None else float(joint.limit.lower)
                high = 1.0 if joint.limit.upper is None else float(joint.limit.upper)
            q[joint.name] = float(rng.uniform(low, high))
        wanted = source.poses({back.get(k, k): v for k, v in q.items()})
        got = kit_poses(built, q)
        root = source.root
        if names[root] not in got:
            return [f"root link '{root}' is missing from the kit"]
        base = got[names[root]] @ np.linalg.inv(source.bodies[root].frame)
        for name, pose in sorted(wanted.items()):
            link = names.get(name)
            if link not in got or f"links.{name}" in allowed.keys:
                continue
            kit = np.linalg.inv(base) @ got[link] @ np.linalg.inv(source.bodies[name].frame)
            far = np.max(np.abs(kit[:3, 3] - pose[:3, 3]))
            if far > FK_TOL or np.max(np.abs(kit[:3, :3] - pose[:3, :3])) > FK_TOL:
                out.append(f"link '{name}': pose differs by {far:.3g} m from the USD's")
        if out:
            return out[:SHOWN]
    return out


def _findings(check: str, problems: list[str], ok: str) -> list[Finding]:
    if not problems:
        return [require(check, True, ok)]
    found = [require(check, False, p + " (not listed in source_differences)") for p in problems]
    if len(found) > SHOWN:
        found = [*found[:SHOWN], require(check, False, f"and {len(found) - SHOWN} more")]
    return found


def _v(values) -> str:
    return "(" + ", ".join(f"{float(v):.6g}" for v in np.ravel(values)) + ")"


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


def _unique(stage, paths) -> dict[str, str]:
    """Prim path -> its name (its displayName where authored), made unique in path order, as
    the import names them."""
    out, taken = {}, set()
    for path in sorted(paths):
        prim = stage.GetPrimAtPath(path)
        want = (prim.GetDisplayName() if prim else "") or path.rsplit("/", 1)[-1] or "root"
        name, n = want, 1
        while name in taken:
            name, n = f"{want}_{n}", n + 1
        taken.add(name)
        out[path] = name
    return out


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
    names = _unique(stage, body_paths)
    joints, joint_paths = [], []
    for kind, label in kinds.items():
        for at, desc in zip(*parsed.get(kind, ([], [])), strict=True):
            joints.append((str(at), label, desc))
            joint_paths.append(str(at))
    joint_names = _unique(stage, joint_paths)
    every = Usd.PrimRange(stage.GetPseudoRoot(), Usd.TraverseInstanceProxies())
    authored = {str(p.GetPath()): i for i, p in enumerate(every)}
    robot = Robot()
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


def kit_poses(built, q: dict[str, float]) -> dict[str, np.ndarray]:
    """Each kit link's pose relative to the kit's root link (yourdfpy's joints)."""
    children = {j.child for j in built.joints}
    root = next(link.name for link in built.links if link.name not in children)
    out = {root: np.eye(4)}
    todo = [root]
    while todo:
        at = todo.pop(0)
        for j in built.joints:
            if j.parent != at:
                continue
            origin = np.eye(4) if j.origin is None else np.asarray(j.origin, dtype=float)
            motion = np.eye(4)
            axis = np.asarray((1.0, 0, 0) if j.axis is None else j.axis, dtype=float)
            value = q.get(j.name, 0.0)
            if j.type in ("revolute", "continuous"):
                motion[:3, :3] = _rodrigues(axis / np.linalg.norm(axis), value)
            elif j.type == "prismatic":
                motion[:3, 3] = axis / np.linalg.norm(axis) * value
            out[j.child] = out[at] @ origin @ motion
            todo.append(j.child)
    return out


def _rodrigues(axis: np.ndarray, angle: float) -> np.ndarray:
    x, y, z = axis
    skew = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    return np.eye(3) + math.sin(angle) * skew + (1 - math.cos(angle)) * skew @ skew
