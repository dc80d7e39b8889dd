"""The kit is the SDFormat robot it was imported from, proved through Drake's SDFormat parser
(libsdformat inside `pydrake`), not simkit's reader: Drake reads the source SDF and the
kit's URDF into two MultibodyPlants, and this compares, under the source's names (robot.json
renames applied; a nested model's `a::b`):

- joint types (a ball as three revolute joints NAME_x, NAME_y, NAME) and position limits;
- every body's mass, CoM and inertia (<= 1e-6 relative), in the kit's link frame;
- every body's pose, and every `<frame>`'s the kit carries as a frame, at 100 seeded
  configurations (<= 1e-6 m, 1e-6 in rotation), relative to
  the world where the source mounts the robot on it, else to the root body;
- masses and joint limits against the kit's composed USD too (kit_usd.py).

Frames: the kit's link frame of a body is its inboard joint's frame (Drake's frame on the
child), the body frame itself for the root, as the import defines it
(importer/formats/sdf/tree.py). A difference passes only where robot.json's
`source_differences` lists it. The source's files (includes, meshes) are laid out from
`NAME.source.assets/SHA256.EXT` (or beside a given file), each checked against its recorded
digest; each top folder is a model (`model://NAME`).

Without `pydrake` the proof cannot run: one failing finding says `pip install drake`. It
fails rather than skips because the user asked for this proof (`--source`, or a build of an
imported spec), and a kit whose source is unproved must not pass silently; the other format's
proofs fail likewise when their reader cannot run.
"""

from __future__ import annotations

import hashlib
import logging
import tempfile
from pathlib import Path, PurePosixPath

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.check.source import kit_usd as source_usd
from simkit.check.source.shared import ABS_LENGTH, REL, SHOWN, Allowed, inertia_close
from simkit.kitio.oneline import one_line

FK_TOL = 1e-6
SEEDS = 100
#: Drake joint types the kit carries as several revolute joints: their name suffixes
#: (translate/ball_joints.py; importer/formats/sdf/universal.py)
SPLIT = {"ball_rpy": ("_x", "_y", ""), "universal": ("_1", "")}


def remake(path: Path, args: dict[str, str]) -> bytes:
    """The kept file made from the original: an SDF is kept byte for byte."""
    return path.read_bytes()


def compare(kit: Kit, path: Path) -> list[Finding]:
    """Findings for the SDF at `path` against the kit's URDF, both read by Drake."""
    try:
        import pydrake  # noqa: F401
    except ImportError:
        why = "the SDFormat source proof reads the source with Drake: pip install drake"
        return [require("source.read", False, why)]
    recorded = kit.doc.get("source") or {}
    if hashlib.sha256(path.read_bytes()).hexdigest() != recorded.get("sha256"):
        return []  # not the file the import read (source.digest fails): never read
    with tempfile.TemporaryDirectory(prefix="simkit-source-") as tmp:
        main, problems = _lay_out(path, recorded, Path(tmp))
        if problems:
            return [require("source.digest", False, p) for p in problems[:SHOWN]]
        try:
            source = Plant(main, Path(tmp))
        except Exception as exc:  # Drake raises RuntimeError with its parser's message
            return [require("source.read", False, f"Drake cannot read the source: {_why(exc)}")]
    try:
        built = Plant(kit.path(kit.urdf), kit.path(".").parent)
    except Exception as exc:
        return [require("source.read", False, f"Drake cannot read the kit's URDF: {_why(exc)}")]
    allowed = Allowed.of(kit.doc)
    return Compare(source, built, allowed).findings() + source_usd.compare(
        kit, usd_view(source), allowed
    )


def usd_view(source: Plant) -> tuple[dict[str, float], dict[str, tuple]]:
    """The source as kit_usd.py compares it with the kit's USD: ({link: mass kg},
    {joint: (revolute or prismatic, (lower, upper) deg or m, or None)})."""
    masses = {name: float(body.default_mass()) for name, body in source.bodies.items()}
    joints: dict[str, tuple] = {}
    for name, joint in source.joints.items():
        kind = joint.type_name()
        if kind not in ("revolute", "prismatic"):
            continue
        low, high = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        scale = np.degrees(1.0) if kind == "revolute" else 1.0
        finite = np.isfinite(low) and np.isfinite(high)
        joints[name] = (kind, (low * scale, high * scale) if finite else None)
    return masses, joints


def _why(exc: Exception) -> str:
    return one_line(" ".join(str(exc).split())[:300])


def _lay_out(given: Path, recorded: dict, folder: Path) -> tuple[Path, list[str]]:
    """The source's files in `folder` as the import read them (relative to the model
    path); the model file's place in it, and problems (a file missing or changed)."""
    digest = recorded.get("sha256")
    kept = given.parent / (given.name.removesuffix(".sdf") + ".assets")
    main, problems = folder / given.name, []
    assets = recorded.get("assets") or {}
    key = next((rel for rel, want in assets.items() if want == digest), given.name)
    up = given.resolve().parents
    base = up[min(len(PurePosixPath(key).parts), len(up)) - 1]  # the model path
    for rel, want in sorted(assets.items()):
        target = (folder / rel).resolve()
        if folder.resolve() not in target.parents or ".." in rel.split("/"):
            problems.append(f"asset '{rel}' lies outside the source's folder")
            continue
        if want == digest:
            main = target
        found = [given] if want == digest else []
        found += [
            base / rel,
            kept / f"{want}{PurePosixPath(rel).suffix.lower()}",
        ]
        for candidate in found:
            if candidate.is_file() and hashlib.sha256(candidate.read_bytes()).hexdigest() == want:
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(candidate.read_bytes())
                break
        else:
            problems.append(f"source file '{rel}' is missing or not the one the import read")
    if not main.is_file():
        main.write_bytes(given.read_bytes())
    for laid in folder.rglob("*.sdf"):
        model_folders(laid, folder)
    return main, problems


def model_folders(path: Path, folder: Path) -> None:
    """`<uri>model://NAME</uri>` (a model folder, which Gazebo reads through its
    model.config and Drake does not) made `model://NAME/FILE`, the newest SDF the laid-out
    model.config names; in the laid-out copy only."""
    import re

    def named(match: re.Match) -> bytes:
        file = _config_file(folder / match.group(1).decode() / "model.config")
        return b"<uri>model://%s/%s</uri>" % (match.group(1), file.encode()) if file else match[0]

    data = path.read_bytes()
    done = re.sub(rb"<uri>\s*model://([A-Za-z0-9_.-]+)/?\s*</uri>", named, data)
    if done != data:
        path.write_bytes(done)


def _config_file(config: Path) -> str | None:
    """The SDF file a model.config names (its newest `<sdf version>`), or None."""
    from lxml import etree

    try:
        root = etree.fromstring(config.read_bytes(), etree.XMLParser(resolve_entities=False))
    except (OSError, etree.XMLSyntaxError):
        return None
    named = []
    for element in root.iter("sdf"):
        version = tuple(int(v) for v in (element.get("version") or "0").split(".") if v.isdigit())
        if (element.text or "").strip():
            named.append((version, element.text.strip()))
    return max(named)[1] if named else None


class Plant:
    """A file read by Drake into a finalized MultibodyPlant; bodies and joints by their
    names scoped below the file's top model (`a::b` in nested model `a`)."""

    def __init__(self, path: Path, models: Path) -> None:
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant

        self.plant = MultibodyPlant(0.0)
        parser = Parser(self.plant)
        for folder in sorted(p for p in models.iterdir() if p.is_dir()):
            if not parser.package_map().Contains(folder.name):
                parser.package_map().Add(folder.name, str(folder))
        logger = logging.getLogger("drake")  # its parse warnings (unsupported friction)
        level = logger.level
        logger.setLevel(logging.ERROR)
        try:
            top = parser.AddModels(str(path))
        finally:
            logger.setLevel(level)
        self.plant.Finalize()
        self.context = self.plant.CreateDefaultContext()
        joints = [self.plant.get_joint(_index("Joint", i)) for i in range(self.plant.num_joints())]
        names = [self.plant.GetModelInstanceName(m) for m in top]
        moving = [n for n in names if any(_moves(j) and self._top(j, [n]) for j in joints)]
        names = moving or names  # a world: its robot, as the import takes it, not scenery
        self.bodies, self.joints = {}, {}
        for i in range(self.plant.num_bodies()):
            body = self.plant.get_body(_index("Body", i))
            if body.index() != self.plant.world_body().index() and self._top(body, names):
                self.bodies[self._scoped(body, names)] = body
        for joint in joints:
            if self._top(joint, names):
                self.joints[self._scoped(joint, names)] = joint
        #: the named frames that are no body's (an SDF `<frame>`; Drake's joint frames too)
        self.frames = {}
        for i in range(self.plant.num_frames()):
            frame = self.plant.get_frame(_index("Frame", i))
            if not frame.is_body_frame() and self._top(frame, names):
                self.frames.setdefault(self._scoped(frame, names), frame)

    def _top(self, element, tops: list[str]) -> bool:
        """Whether `element` lies in one of the models `tops` (or a model nested in one)."""
        instance = self.plant.GetModelInstanceName(element.model_instance())
        return any(instance == t or instance.startswith(t + "::") for t in tops)

    def _scoped(self, element, tops: list[str]) -> str:
        instance = self.plant.GetModelInstanceName(element.model_instance())
        for top in tops:
            if instance.startswith(top + "::"):
                return f"{instance[len(top) + 2 :]}::{element.name()}"
        return element.name()

    def inboard(self, body):
        """The joint whose child is `body` (None for a free root)."""
        for joint in self.joints.values():
            if (
                joint.child_body().index() == body.index()
                and joint.type_name() != "quaternion_floating"
            ):
                return joint
        return None

    def kit_frame(self, body) -> np.ndarray:
        """X_BK: the kit's link frame in the body frame (the inboard joint's frame)."""
        joint = self.inboard(body)
        if joint is None:
            return np.eye(4)
        return joint.frame_on_child().GetFixedPoseInBodyFrame().GetAsMatrix4()

    def pose(self, body) -> np.ndarray:
        return self.plant.EvalBodyPoseInWorld(self.context, body).GetAsMatrix4()

    def frame_pose(self, frame) -> np.ndarray:
        return frame.CalcPoseInWorld(self.context).GetAsMatrix4()


def _moves(joint) -> bool:
    return joint.type_name() not in ("weld", "quaternion_floating")


def _index(kind: str, i: int):
    from pydrake.multibody import tree

    return getattr(tree, f"{kind}Index")(i)


class Compare:
    """The source plant against the kit plant (`findings`)."""

    def __init__(self, source: Plant, kit: Plant, allowed: Allowed) -> None:
        self.s, self.k, self.allowed = source, kit, allowed

    def kit_body(self, name: str):
        return self.k.bodies.get(self.allowed.links.get(one_line(name), name))

    def kit_joint(self, name: str):
        """The kit's joint of source joint `name`; Drake files a joint under its child's
        model, so a joint of the top model to a nested link is also tried by its own name."""
        found = self.k.joints.get(self.allowed.joints.get(one_line(name), name))
        if found is None and "::" in name:
            return self.kit_joint(name.rpartition("::")[2])
        return found

    def listed(self, key: str) -> bool:
        return key in self.allowed.keys

    def findings(self) -> list[Finding]:
        out = _findings(
            "source.joints", self.joints(), f"{len(self.s.joints)} joints: types and limits agree"
        )
        out += _findings(
            "source.links",
            self.links(),
            f"{len(self.s.bodies)} bodies: masses, CoMs and inertias agree",
        )
        return out + _findings(
            "source.fk", self.fk(), f"every body's pose agrees at {SEEDS} seeded configurations"
        )

    def joints(self) -> list[str]:
        out = []
        for name, joint in sorted(self.s.joints.items()):
            kind = joint.type_name()
            if kind == "quaternion_floating" or self.listed(f"joints.{name}"):
                continue
            if kind in SPLIT:
                parts = [self.kit_joint(f"{name}{x}") for x in SPLIT[kind]]
                if any(p is None or p.type_name() != "revolute" for p in parts):
                    said = " and ".join(name + x for x in SPLIT[kind])
                    out.append(
                        f"joint '{name}': a {kind}, not the revolute joints {said} in the kit"
                    )
                continue  # Drake reads no limits of either (a universal's: Drake 1.51)
            other = self.kit_joint(name)
            if other is None:
                if kind != "weld":  # a weld may be merged away (a fixed joint's link kept)
                    out.append(f"joint '{name}' is missing from the kit")
                continue
            if other.type_name() != kind and not self.listed(f"joints.{name}.type"):
                out.append(f"joint '{name}': {kind} in the source, {other.type_name()} in the kit")
                continue
            if kind in ("revolute", "prismatic"):
                out += self._limits(name, joint, other)
        return out

    def _limits(self, name: str, joint, other) -> list[str]:
        out = []
        for attr, a, b in (
            ("lower", joint.position_lower_limits()[0], other.position_lower_limits()[0]),
            ("upper", joint.position_upper_limits()[0], other.position_upper_limits()[0]),
        ):
            if self.listed(f"joints.{name}.{attr}") or (np.isinf(a) and np.isinf(b)):
                continue
            if not np.isfinite(a) or not np.isfinite(b) or abs(a - b) > REL * abs(a) + ABS_LENGTH:
                out.append(f"joint '{name}': {attr} {a:.9g} in the source, {b:.9g} in the kit")
        return out

    def links(self) -> list[str]:
        out = []
        for name, body in sorted(self.s.bodies.items()):
            other = self.kit_body(name)
            if other is None:
                if not self.listed(f"links.{name}") and body.default_mass() > 0:
                    out.append(f"link '{name}' is missing from the kit")
                continue
            m0, c0, i0 = _mass(body, self.s.kit_frame(body))
            m1, c1, i1 = _mass(other, np.eye(4))
            key = f"links.{name}"
            if abs(m0 - m1) > REL * m0 and not self.listed(f"{key}.mass"):
                out.append(f"link '{name}': mass {m0:.9g} kg in the source, {m1:.9g} in the kit")
            if m0 == 0:
                continue
            if np.max(np.abs(c0 - c1)) > REL * np.max(np.abs(c0)) + ABS_LENGTH and not self.listed(
                f"{key}.com"
            ):
                out.append(f"link '{name}': CoM {_v(c0)} m in the source, {_v(c1)} in the kit")
            if not inertia_close(i0, i1) and not self.listed(f"{key}.inertia"):
                out.append(
                    f"link '{name}': inertia {_v(np.diag(i0))} kg m^2 in the source, "
                    f"{_v(np.diag(i1))} in the kit"
                )
        return out

    def fk(self) -> list[str]:
        world = self.s.plant.world_body().index()
        mounted = any(
            j.parent_body().index() == world and j.type_name() != "quaternion_floating"
            for j in self.s.joints.values()
        )
        roots = [b for b in self.s.bodies.values() if self.s.inboard(b) is None]
        ref = None if mounted or not roots else roots[0]
        ref_kit = None if ref is None else self.kit_body(self._name(ref))
        if ref is not None and ref_kit is None:
            return [f"the root body '{ref.name()}' is missing from the kit"]
        pairs = [(n, b, self.kit_body(n)) for n, b in sorted(self.s.bodies.items())]
        pairs = [(n, b, k) for n, b, k in pairs if k is not None]
        frames = [(n, f, self.kit_body(n)) for n, f in sorted(self.s.frames.items())]
        frames = [(n, f, k) for n, f, k in frames if k is not None and n not in self.s.bodies]
        rng = np.random.default_rng(0)
        worst: dict[str, float] = {}
        for _ in range(SEEDS):
            self._configure(rng)
            xs0 = np.eye(4) if ref is None else self.s.pose(ref)
            xk0 = np.eye(4) if ref_kit is None else self.k.pose(ref_kit)
            poses = [(n, self.s.pose(b) @ self.s.kit_frame(b), k) for n, b, k in pairs]
            poses += [(n, self.s.frame_pose(f), k) for n, f, k in frames]  # kit frames
            for name, pose, other in poses:
                xs = np.linalg.inv(xs0) @ pose
                xk = np.linalg.inv(xk0) @ self.k.pose(other)
                err = float(np.max(np.abs(xs[:3] - xk[:3])))
                if err > FK_TOL:
                    worst[name] = max(worst.get(name, 0.0), err)
        return [
            f"link '{n}': pose off by up to {e:.3g} m (or rotation) at seeded configurations"
            for n, e in worst.items()
        ]

    def _name(self, body) -> str:
        return next(n for n, b in self.s.bodies.items() if b.index() == body.index())

    def _configure(self, rng) -> None:
        """One seeded configuration, set in both plants: each revolute or prismatic joint
        in its source range (else +-pi rad, +-0.1 m), a ball as three angles x, y, z."""
        from pydrake.math import RollPitchYaw, RotationMatrix

        for name, joint in sorted(self.s.joints.items()):
            kind = joint.type_name()
            if kind == "ball_rpy":
                angles = rng.uniform(-np.pi, np.pi, 3)
                rot = RotationMatrix.MakeXRotation(angles[0])
                rot = rot.multiply(RotationMatrix.MakeYRotation(angles[1]))
                rot = rot.multiply(RotationMatrix.MakeZRotation(angles[2]))
                joint.set_angles(self.s.context, RollPitchYaw(rot).vector())
                for suffix, angle in zip(("_x", "_y", ""), angles, strict=True):
                    other = self.kit_joint(name + suffix)
                    if other is not None and other.num_positions() == 1:
                        other.set_angle(self.k.context, angle)
            elif kind == "universal":
                angles = [self._draw(joint, k, rng) for k in range(2)]
                joint.set_angles(self.s.context, angles)
                for suffix, angle in zip(SPLIT[kind], angles, strict=True):
                    other = self.kit_joint(name + suffix)
                    if other is not None and other.num_positions() == 1:
                        other.set_angle(self.k.context, angle)
            elif kind in ("revolute", "prismatic"):
                value = self._draw(joint, 0, rng)
                _set(joint, self.s.context, value)
                other = self.kit_joint(name)
                if other is not None and other.num_positions() == 1:
                    _set(other, self.k.context, value)

    @staticmethod
    def _draw(joint, k: int, rng) -> float:
        """A value of the joint's `k`th position in its range (else +-pi rad, +-0.1 m)."""
        span = 0.1 if joint.type_name() == "prismatic" else np.pi
        low, high = joint.position_lower_limits()[k], joint.position_upper_limits()[k]
        return rng.uniform(low if np.isfinite(low) else -span, high if np.isfinite(high) else span)


def _set(joint, context, value: float) -> None:
    """A revolute (rad) or prismatic (m) joint's position."""
    if joint.type_name() == "revolute":
        joint.set_angle(context, value)
    elif joint.type_name() == "prismatic":
        joint.set_translation(context, value)


def _mass(body, x_bk: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """(kg, CoM m, inertia about the CoM kg m^2) in the kit frame K (`x_bk`: K in B)."""
    spatial = body.default_spatial_inertia()
    mass = float(spatial.get_mass())
    com = np.asarray(spatial.get_com())
    about_origin = spatial.CalcRotationalInertia().CopyToFullMatrix3()
    about_com = about_origin - mass * (float(com @ com) * np.eye(3) - np.outer(com, com))
    rot = x_bk[:3, :3].T
    return mass, rot @ (com - x_bk[:3, 3]), rot @ about_com @ rot.T


def _findings(check: str, problems: list[str], ok: str) -> list[Finding]:
    if not problems:
        return [require(check, True, ok)]
    out = [require(check, False, x + " (not listed in source_differences)") for x in problems]
    return out[:SHOWN] + (
        [require(check, False, f"and {len(out) - SHOWN} more")] if len(out) > SHOWN else []
    )


def _v(values) -> str:
    return "(" + ", ".join(f"{float(v):.6g}" for v in np.ravel(values)) + ")"
