"""A read SDFormat model (reader.py) to the source model the shared translation takes
(read/model.py `Robot`: links and joints in URDF terms, numbers as the floats computed here).

Frames follow the specification (frames.py). A URDF joint turns about its child link's
origin; an SDF joint has its own frame (by default its child link's, moved by its `<pose>`).
A link's kit frame is therefore its first parent joint's frame (the link frame itself for
the root link), and its inertial, visuals and collisions are expressed in that frame; the
source check applies the same rule through Drake (the joint's frame on its child).

Joints: revolute (no finite limits: continuous), continuous, prismatic, fixed, ball ->
`spherical` (three revolute joints, translate/ball_joints.py); a joint to `world` mounts the
robot (a fixed base); a link's second parent joint (a closed loop) stays in the tree for the
translation to leave out (translate/loops.py); a universal joint is two revolute joints
(universal.py). A `<frame>` is a kit frame: a massless
leaf link on a fixed joint from the link it is attached to (the canonical link for the model
frame, the world where a joint mounts the model). Revolute2, screw and gearbox
joints are one line each: a kit's joints turn about one axis each. Nested model names are
scoped (`a::b`); fixups/names.py makes them legal spec names and records the renames.
"""

from __future__ import annotations

import numpy as np

from simkit.importer.formats.sdf import universal
from simkit.importer.formats.sdf.elements import (
    axis_in_joint,
    in_model,
    limits,
    origin,
    vec,
)
from simkit.importer.formats.sdf.frames import (
    MODEL,
    WORLD,
    Frames,
    inverse,
    numbers,
    pose_of,
    scoped,
)
from simkit.importer.read.model import At, Geometry, Inertial, Joint, Link, Material, Robot, Shape

#: SDF joint type -> URDF type; the others are refused
KINDS = {
    "revolute": "revolute",
    "continuous": "continuous",
    "prismatic": "prismatic",
    "fixed": "fixed",
    "ball": "spherical",
}


class Model:
    """The flattened model: links and joints by scoped name, their frame graph."""

    def __init__(self, source) -> None:
        self.source = source
        self.frames = Frames(source)
        self.links: dict[str, object] = {}
        self.joints: dict[str, object] = {}
        #: the `<frame>`s the model names (not the merged includes' model frames)
        self.named: dict[str, object] = {}
        self.canonical = ""
        self._flatten(source.model, "")
        given = source.model.get("canonical_link")
        self.canonical = given or self.canonical

    def _flatten(self, model, scope: str) -> None:
        first_link = None
        for child in model:
            if not isinstance(child.tag, str) or child.tag not in (
                "link",
                "joint",
                "frame",
                "model",
            ):
                continue
            name = scoped(scope, child.get("name") or "")
            pose = child.find("pose")
            rel = None if pose is None else pose.get("relative_to") or pose.get("frame") or None
            if child.tag == "link":
                self.links[name] = child
                first_link = first_link or name
                self.canonical = self.canonical or ("" if scope else name)
                self.frames.add(
                    name, child, scoped(scope, rel or MODEL), pose_of(self.source, pose)
                )
            elif child.tag == "frame":
                attached = scoped(scope, child.get("attached_to") or MODEL)
                self.frames.attached[name] = attached
                if not name.rpartition("::")[2].startswith("_merged__"):
                    self.named[name] = child
                self.frames.add(name, child, scoped(scope, rel) if rel else attached,
                                pose_of(self.source, pose))  # fmt: skip
            elif child.tag == "joint":
                self.joints[name] = child
                kid = scoped(scope, (child.findtext("child") or "").strip())
                self.frames.attached[name] = kid  # a joint's frame moves with its child
                self.frames.add(name, child, scoped(scope, rel) if rel else kid,
                                pose_of(self.source, pose))  # fmt: skip
                for tag in ("parent", "child"):
                    element = child.find(tag)
                    if element is not None:
                        element.set("scoped", scoped(scope, (element.text or "").strip()))
                for xyz in child.iter("xyz"):
                    xyz.set("scope", scope)
            else:
                self.frames.add(
                    name, child, scoped(scope, rel or MODEL), pose_of(self.source, pose)
                )
                self._flatten(child, name)
                canonical = child.get("canonical_link")
                self.frames.attached[name] = scoped(name, canonical) if canonical else name + "::"
        if scope:
            self.frames.attached.setdefault(scope + "::", first_link or scope)

    def link_of(self, name: str, element) -> str:
        if name == WORLD:
            return WORLD
        found = self.frames.link_of(name, set(self.links), element)
        while found.endswith("::"):
            found = self.frames.link_of(self.frames.attached[found], set(self.links), element)
        return found


def to_robot(source) -> tuple[Robot, list[str]]:
    """The source model of the model, and the joints mounting it on the world. Each node is
    on its SDF element's line (the model's where the element has none)."""
    model = Model(source)
    if not model.links:
        raise source.fail(source.model, "the model has no link")
    line = source.model.sourceline
    kit_frame: dict[str, str] = {}
    ends: list[tuple[str, str, str, object]] = []
    for name, joint in model.joints.items():
        parent = model.link_of(joint.find("parent").get("scoped"), joint.find("parent"))
        child = model.link_of(joint.find("child").get("scoped"), joint.find("child"))
        if child in (WORLD, MODEL) or parent == MODEL:
            raise source.fail(joint, "a joint must join two links (or a link to the world)")
        ends.append((name, parent, child, joint))
        turned = joint.get("type") == "universal" and child not in kit_frame
        kit_frame.setdefault(child, universal.turned(model, name, joint) if turned else name)
    roots = [n for n in model.links if n not in kit_frame]
    if len(roots) > 1:
        raise source.fail(
            model.links[roots[1]],
            f"{len(roots)} links hang from no joint ({', '.join(roots[:4])}): "
            + ("static scenery" if source.static else "bodies free in the world")
            + ", not one robot; import one per file",
        )
    world = [n for n, p, _, _ in ends if p == WORLD]
    links: list[Link] = []
    if world:  # the world a joint mounts the model on: a link of the tree
        links.append(Link(WORLD, At("link", WORLD, model.joints[world[0]].sourceline or line)))
    for name, element in model.links.items():
        links.append(_link(model, name, element, kit_frame.get(name, name), line))
    joints: list[Joint] = []
    for name, parent, child, joint in ends:
        if joint.get("type") == "universal":
            two, mid = universal.emit(model, (name, parent, child, joint), kit_frame, line)
            joints += two
            links.append(mid)
        else:
            joints.append(_joint(model, name, joint, (parent, child), kit_frame, line))
    _frames(links, joints, model, kit_frame, WORLD if world else model.canonical, line)
    materials = tuple(g.material for link in links for g in link.visuals if g.material)
    title = source.model.get("name") or "robot"
    robot = Robot(At("robot", title, line), title, tuple(links), tuple(joints), materials)
    return robot, world  # a computed number that is not finite: refused by formats.load


def _frames(links: list, joints: list, model: Model, kit_frame: dict[str, str], on_model: str,
            line: int | None) -> None:  # fmt: skip
    """Each `<frame>`: a kit frame, a massless leaf link on a fixed joint from the link it
    is attached to (one attached to the model frame: the world where a joint mounts the
    model on it, else the canonical link, which carries the model frame)."""
    taken = set(model.links) | set(model.joints) | set(model.named)
    for name, element in model.named.items():
        link = model.link_of(name, element)
        link = on_model if link == MODEL else link
        joint = _free(f"{name}_joint", taken)
        here = element.sourceline or line
        parent = in_model(model, kit_frame.get(link, link), element)
        pose = origin(inverse(parent) @ model.frames.in_model(name, element), here)
        joints.append(Joint(joint, "fixed", At("joint", joint, here), link, name, pose))
        links.append(Link(name, At("link", name, here)))


def _free(name: str, taken: set[str]) -> str:
    out, n = name, 1
    while out in taken:
        out, n = f"{name}_{n}", n + 1
    taken.add(out)
    return out


def _placed(model: Model, element, link: str, kit: np.ndarray) -> np.ndarray:
    """The pose of a link's child element (its `<pose>`, relative to the link unless it
    says otherwise) in the link's kit frame (`kit`: that frame in the model)."""
    pose = element.find("pose")
    rel = None if pose is None else pose.get("relative_to")
    base = (
        model.frames.in_model(scoped(link.rpartition("::")[0], rel), pose)
        if rel
        else (model.frames.in_model(link))
    )
    return inverse(kit) @ base @ pose_of(model.source, pose)


def _link(model: Model, name: str, element, frame: str, line: int | None) -> Link:
    """A link: its inertial (1 kg, unit inertia where the SDF gives none, as SDFormat's
    defaults), visuals and collisions, in its kit frame `frame`."""
    line = element.sourceline or line
    kit = model.frames.in_model(frame, element)
    inertial = element.find("inertial")
    if inertial is not None and inertial.get("auto") in ("true", "1"):
        raise model.source.fail(inertial, "automatic inertia (<inertial auto>): not read")
    pose = origin(
        _placed(model, inertial, name, kit)
        if inertial is not None
        else inverse(kit) @ model.frames.in_model(name),
        line,
    )
    mass = 1.0 if inertial is None or inertial.find("mass") is None else numbers(
        model.source, inertial.find("mass"), inertial.findtext("mass"), 1)[0]  # fmt: skip
    moments = inertial.find("inertia") if inertial is not None else None
    terms = []
    for key, default in (
        ("ixx", 1.0),
        ("iyy", 1.0),
        ("izz", 1.0),
        ("ixy", 0.0),
        ("ixz", 0.0),
        ("iyz", 0.0),
    ):
        found = None if moments is None else moments.find(key)
        terms.append(default if found is None else numbers(model.source, found, found.text, 1)[0])
    at = At("inertial", None, line)
    inertia = tuple(terms) if mass > 0 else None  # a massless link's inertia is not read
    mass_at, inertia_at = At("mass", None, line), At("inertia", None, line)
    drawn = {
        tag: tuple(
            g
            for k, shape in enumerate(element.findall(tag))
            if (g := _shape(model, name, shape, (tag, k), kit, line)) is not None
        )
        for tag in ("visual", "collision")
    }
    return Link(
        name,
        At("link", name, line),
        Inertial(at, pose, float(mass), mass_at, inertia, inertia_at),  # type: ignore[arg-type]
        drawn["visual"],
        drawn["collision"],
    )


def _shape(model: Model, name: str, shape, which: tuple[str, int], kit: np.ndarray,
           line: int | None) -> Geometry | None:  # fmt: skip
    """One visual or collision (`which`: its tag and index); shapes a URDF cannot hold are
    reported as dropped (None)."""
    tag, k = which
    geometry = shape.find("geometry")
    kind = (
        next((g for g in geometry if isinstance(g.tag, str)), None)
        if geometry is not None
        else None
    )
    if kind is None or kind.tag not in ("box", "sphere", "cylinder", "capsule", "mesh"):
        if model.source.report is not None and kind is not None and kind.tag != "empty":
            model.source.report.dropped(model.source, shape, f"<{kind.tag}> geometry: no URDF form")
        return None
    line = shape.sourceline or line
    pose = origin(_placed(model, shape, name, kit), line)
    src = model.source

    def num(field: str, count: int = 1, default=None) -> list[float]:
        element = kind.find(field)
        if element is None:
            if default is None:
                raise src.fail(kind, f"<{kind.tag}> has no <{field}>")
            return default
        return numbers(src, element, element.text, count)

    if kind.tag == "box":
        sizes: dict = {"size": vec(num("size", 3))}
    elif kind.tag == "sphere":
        sizes = {"radius": num("radius")[0]}
    elif kind.tag in ("cylinder", "capsule"):
        sizes = {"radius": num("radius")[0], "length": num("length")[0]}
    else:
        sizes = {"filename": (kind.findtext("uri") or "").strip()}
        sizes["scale"] = vec(num("scale", 3, [1.0, 1.0, 1.0]))
    drawn = Shape(kind.tag, At(kind.tag, None, line), **sizes)
    diffuse = shape.find("material/diffuse") if tag == "visual" else None
    material = None
    if diffuse is not None:
        rgba = numbers(src, diffuse, diffuse.text)
        rgba = (rgba + [1.0] * 4)[:4] if len(rgba) >= 3 else [0.7, 0.7, 0.7, 1.0]
        called = f"sdf_{name}_{tag}{k}"
        material = Material(At("material", called, line), called, vec(rgba))  # type: ignore[arg-type]
    return Geometry(At(tag, shape.get("name") or None, line), pose, drawn, material)


def _joint(model: Model, name: str, joint, link_ends: tuple[str, str], kit_frame,
           line: int | None) -> Joint:  # fmt: skip
    """A joint between `link_ends` (parent, child), its origin in the parent's kit frame."""
    src = model.source
    kind = (joint.get("type") or "").strip()
    if kind not in KINDS:
        raise src.fail(
            joint, f"a {kind or 'typeless'} joint: a kit's joints turn about one axis each"
        )
    line = joint.sourceline or line
    parent, child = link_ends
    x_joint = model.frames.in_model(name, joint)
    parent_frame = kit_frame.get(parent, parent)
    pose = origin(inverse(in_model(model, parent_frame, joint)) @ x_joint, line)
    at = At("joint", name, line)
    if kind in ("fixed", "ball"):
        return Joint(name, KINDS[kind], at, parent, child, pose)
    axis = vec(axis_in_joint(model, joint, "axis", x_joint))
    kind, limit, dynamics = limits(src, joint.find("axis"), kind, line)
    return Joint(name, kind, at, parent, child, pose, axis, At("axis", None, line), limit, dynamics)  # type: ignore[arg-type]
