"""The source model (read/model.py) to a spec dict: the tree, its root, frames, poses and
the report."""

from __future__ import annotations

import math

import numpy as np

from simkit.importer.diagnostics import Report
from simkit.importer.read.source import Source
from simkit.importer.translate.ball_joints import expand as expand_ball_joints
from simkit.importer.translate.joints import first_leaders, joint_spec, mimic_limits
from simkit.importer.translate.links import has_geometry, has_mass, link_spec
from simkit.importer.translate.meshes import MeshWriter
from simkit.importer.translate.solids import DENSITY, MAX_SIDE, add_solids
from simkit.kitio.oneline import one_line
from simkit.spec.bounds import MAX_BODIES
from simkit.spec.urdf_blocks import TAGS as URDF_BLOCK_TAGS


def tree(source: Source) -> tuple[dict, dict, str]:
    """Links by name, joints by child, and the root link (source model nodes); errors for
    cycles and orphans."""
    robot = source.robot
    links: dict = {}
    for link in robot.links:
        if not link.name:
            raise source.fail(link.at, "a link needs a name")
        if link.name in links:
            raise source.fail(link.at, f"link '{link.name}' is defined twice, differently")
        links[link.name] = link
    if not links:
        raise source.fail(robot.at, "no <link> in the robot")
    if len(links) > MAX_BODIES:  # refused before any per-link work (a 10,000-link chain)
        raise source.fail(
            robot.at, f"{len(links)} links: a spec holds at most {MAX_BODIES} (spec/bounds.py)"
        )
    by_child: dict = {}
    joint_names: set = set()
    for joint in robot.joints:
        if joint.name in joint_names:
            raise source.fail(joint.at, f"joint '{joint.name}' is defined twice, differently")
        joint_names.add(joint.name)
        for end, link in (("parent", joint.parent), ("child", joint.child)):
            if link is not None and link not in links:
                raise source.fail(joint.at, f"unknown {end} link '{link}'")
        if joint.child is None:
            raise source.fail(joint.at, "a joint needs <child link=...>")
        if joint.child in by_child:
            raise source.fail(joint.at, f"link '{joint.child}' already has a parent joint")
        by_child[joint.child] = joint
    roots = [name for name in links if name not in by_child]
    if not roots:
        raise source.fail(
            next(iter(by_child.values())).at, "the joints form a cycle (no root link)"
        )
    if len(roots) > 1:
        raise source.fail(
            links[roots[1]].at, f"links {roots[:3]} have no parent: more than one root"
        )
    reached = {roots[0]}  # every link must reach the root; each link is walked once
    for name in links:
        path, at = {}, name  # an insertion-ordered set: linear in the chain's length
        while at not in reached:
            if at in path:
                raise source.fail(by_child[at].at, "the joints form a cycle")
            path[at] = None
            at = by_child[at].parent
        reached.update(path)
    return links, by_child, roots[0]


def _children(by_child: dict) -> dict[str, list[str]]:
    out: dict[str, list[str]] = {}
    for child, joint in by_child.items():
        out.setdefault(joint.parent, []).append(child)
    return out


def _loads(links, kids, by_child, root) -> dict[str, tuple[float, float]]:
    """Per link: mass (kg) of its subtree and a lever arm (m), the longest chain of joint
    offsets below it or CoM offset (a long link without children, such as a neck, holds its
    CoM that far; at least 0.1 m). Children before parents, without recursion: a chain of
    10,000 links takes linear time."""
    order, stack = [], [root]
    while stack:
        name = stack.pop()
        order.append(name)
        stack.extend(kids.get(name, []))
    out: dict[str, tuple[float, float]] = {}
    for name in reversed(order):
        mass, arm = 0.0, 0.0
        link = links[name]
        if has_mass(link):
            mass = link.inertial.mass
            arm = float(np.linalg.norm(link.inertial.origin.xyz))  # its own CoM is a lever arm
        for child in kids.get(name, []):
            sub_mass, sub_arm = out[child]
            offset = float(np.linalg.norm(by_child[child].origin.xyz))
            mass += sub_mass
            arm = max(arm, offset + sub_arm)
        out[name] = (mass, max(arm, 0.1))
    return out


def _frame_links(links, by_child, kids, root) -> set[str]:
    """Massless, geometry-free leaves on fixed joints: they become frames."""
    return {
        name
        for name, link in links.items()
        if name != root
        and not kids.get(name)
        and by_child[name].type == "fixed"
        and not has_mass(link)
        and not has_geometry(link)
    }


def materials_of(source: Source) -> dict[str, tuple]:
    """Each named material's colour (the first of a name), anywhere in the document."""
    out: dict[str, tuple] = {}
    for material in source.robot.materials:
        out.setdefault(material.name, material.rgba)
    return out


def convert(
    source: Source,
    name: str,
    writer: MeshWriter,
    report: Report,
    floating: bool,
    hull_collision: bool = False,
    density: float | None = None,
) -> dict:
    """The spec dict for the whole robot. `density` (kg/m^3): massless links with a solid
    get its mass at it (`_estimated_mass`; None: the placeholder speck)."""
    for element in source.robot.others:
        if element.tag not in URDF_BLOCK_TAGS:
            report.dropped(
                source, element, "simkit writes its own (URDF, MJCF, ros2_control, SRDF)"
            )
    expand_ball_joints(source)  # spherical joints: three revolute ones (ball_joints.py)
    links, by_child, root = tree(source)
    kids = _children(by_child)
    frames = _frame_links(links, by_child, kids, root)
    loads = _loads(links, kids, by_child, root)
    materials, colours = materials_of(source), {}
    root_is_frame = not has_mass(links[root]) and not has_geometry(links[root]) and not floating
    spec_links, spec_joints, spec_frames = [], [], []
    spec_root = root if root_is_frame else _world(links)
    if not root_is_frame:
        joint_type = "floating" if floating else "fixed"
        spec_joints.append(
            {"name": f"{root}_{joint_type}", "type": joint_type, "parent": spec_root, "child": root}
        )
    drawn = any(link.visuals for link in links.values())
    for link_name in links:  # document order
        if link_name == spec_root:
            continue
        if link_name in frames:
            joint = by_child[link_name]
            js = joint_spec(source, joint, report, (0.0, 0.1))
            frame = {"name": link_name, "parent": js["parent"]}
            frame.update({k: js[k] for k in ("xyz", "rpy") if k in js})
            if js["name"] != f"{link_name}_joint":  # the URDF's own joint name, kept
                frame["joint"] = js["name"]
            spec_frames.append(frame)
            continue
        estimate = density if _estimated_mass(link_name, links, by_child) else None
        spec_links.append(
            link_spec(
                source,
                links[link_name],
                writer,
                report,
                materials,
                colours,
                hull_collision,
                estimate,
                volume_mass=not drawn,
            )
        )
        if link_name in by_child:
            spec_joints.append(joint_spec(source, by_child[link_name], report, loads[link_name]))
    if floating and not any(link.collisions for link in source.robot.links):
        if not any(link.visuals for link in source.robot.links):
            _estimated_solids(source, spec_links, spec_joints, report)
        else:
            _visual_collision(source, spec_links, report)
    if floating and has_mass(links[root]) is False and not has_geometry(links[root]):
        report.changed(source, links[root].at, "massless root of a floating base")
    spec: dict = {
        "name": name,
        "title": one_line(source.robot.name or name),
        "description": f"Imported from {one_line(source.path.name)} by simkit import.",
        "sources": [one_line(source.path.name)],
        "root": spec_root,
    }
    if floating:
        spec["floating_base"] = True
        # a floor to stand on (the legged checks drop the robot onto it)
        spec["mjcf"] = {"floor": {"name": "floor", "size": [0.0, 0.0, 0.05]}}
    tool = _deepest(spec_root, spec_joints, spec_frames)
    if tool and any(j["type"] not in ("fixed", "floating") for j in spec_joints):
        # no tool on a robot without joints (a rigid drone): nothing moves it
        spec["tool_frame"] = tool
    if colours:
        spec["materials"] = [{"name": n, "rgba": list(c)} for c, n in colours.items()]
    spec_joints = _depth_first(spec_joints, spec_root, _ancestors(tool, spec_joints, spec_frames))
    _check_mimics(source, spec_joints, report)
    rank = {j["child"]: i for i, j in enumerate(spec_joints)}
    spec_links.sort(key=lambda link: rank.get(link["name"], -1))
    movable = [j for j in spec_joints if j["type"] not in ("fixed", "floating")]
    if movable:
        home = {j["name"]: _home(j) for j in movable}
        _report_mid_range(source, movable, home, report)
        for j in movable:  # a mimic joint follows its leader
            if "mimic" in j and j["mimic"]["joint"] in home:
                m = j["mimic"]
                home[j["name"]] = m["multiplier"] * home[m["joint"]] + m["offset"]
        spec["poses"] = {"home": [home[j["name"]] for j in movable]}
    spec["links"] = spec_links
    spec["joints"] = spec_joints
    if spec_frames:
        spec["frames"] = spec_frames
    return spec


def _world(links: dict) -> str:
    """The spec's root frame above the URDF's root link: `world`, unless a URDF link (one
    with mass or geometry, which names.py then renames) already has that name."""
    name, count = "world", 0
    while name in links:
        count += 1
        name = f"world_frame{count if count > 1 else ''}"
    return name


def _estimated_mass(name: str, links: dict, by_child: dict) -> bool:
    """Whether a massless link's mass comes from its solid (masses.py): always where the URDF
    gives no link a mass, else for a link on a movable joint (a massless link on a fixed
    joint is the author's frame or housing, merged into its parent)."""
    if has_mass(links[name]):
        return False
    if not any(has_mass(link) for link in links.values()):
        return True
    return name in by_child and by_child[name].type not in ("fixed", "")


def _visual_collision(source: Source, spec_links: list[dict], report: Report) -> None:
    """A floating robot whose URDF has no `<collision>` at all (a visual-only model such as
    a biomechanics body) would fall through the floor: each link with a visual solid collides with
    that solid's convex hull instead (`collision: mesh`), marked estimated and reported."""
    done = 0
    for link in spec_links:
        if link.get("solid") and link.get("collision") == "primitives":
            link.pop("collision_primitives", None)
            link["collision"] = "mesh"
            link["estimated"] = [*link.get("estimated", []), "collision"]
            done += 1
    if done:
        report.estimated(
            source,
            source.robot.at,
            f"no <collision> in the {source.noun}: {done} links collide with their visual solid's "
            "convex hull (a floating base needs something to stand on)",
        )


def _estimated_solids(source: Source, links: list[dict], joints: list[dict], report) -> None:
    """A floating robot with no geometry at all (a masses-only humanoid) gets an
    estimated box per link with a mass (solids.py), reported on one line."""
    done = add_solids(links, joints)
    if done:
        report.estimated(
            source,
            source.robot.at,
            f"no <visual> or <collision> in the {source.noun}: {done} links with a mass get a box "
            f"spanning their origin, child joints and CoM, as thick as holds the mass at "
            f"{DENSITY:g} kg/m^3 up to {MAX_SIDE:g} m (solid and collision; a floating base "
            "needs something to stand on)",
        )


def _check_mimics(source: Source, joints: list[dict], report: Report) -> None:
    """A mimic whose leader is not a movable joint of the spec is reported and dropped; a
    follower whose limits contradict its mimic gets the leader's mapped range (joints.py)."""
    movable = {j["name"]: j for j in joints if j["type"] not in ("fixed", "floating")}
    for joint in joints:
        mimic = joint.get("mimic")
        if mimic is not None and (mimic["joint"] not in movable or mimic["joint"] == joint["name"]):
            del joint["mimic"]
            joint.pop("actuated", None)
            report.dropped(
                source,
                _mimic_at(source, joint["name"]),
                f"'{joint['name']}' mimics '{mimic['joint']}', not a movable joint: "
                "imported as independent",
            )
    first_leaders(source, joints, report)
    for joint in joints:
        if "mimic" in joint:
            mimic_limits(source, joint, movable[joint["mimic"]["joint"]], report)


def _mimic_at(source: Source, name: str):
    """Where the source's joint `name` gives its `<mimic>` (its robot, when it does not)."""
    joint = source.robot.joint(name)
    return joint.mimic.at if joint is not None and joint.mimic is not None else source.robot.at


def _ancestors(tool: str | None, joints: list[dict], frames: list[dict]) -> set[str]:
    """The tool frame and every link above it."""
    parent = {j["child"]: j["parent"] for j in joints}
    parent.update({f["name"]: f["parent"] for f in frames})
    out, node = set(), tool
    while node is not None and node not in out:
        out.add(node)
        node = parent.get(node)
    return out


def _depth_first(joints: list[dict], root: str, first: set[str] = frozenset()) -> list[dict]:
    """Joints depth first from the root, siblings in document order except that the branch
    to the tool (`first`: the links above it) comes first, so the first movable joint is on
    the tool's chain (the planning group and FK reference start at its parent). This is the
    spec's tree order, which `poses` follow."""
    by_parent: dict[str, list[dict]] = {}
    for joint in joints:
        by_parent.setdefault(joint["parent"], []).append(joint)
    for siblings in by_parent.values():
        siblings.sort(key=lambda j: j["child"] not in first)  # stable: document order kept
    out: list[dict] = []
    stack = list(reversed(by_parent.get(root, [])))
    while stack:
        joint = stack.pop()
        out.append(joint)
        stack.extend(reversed(by_parent.get(joint["child"], [])))
    return out


def _report_mid_range(source: Source, movable: list[dict], home: dict, report: Report) -> None:
    """One line per joint whose home is not the URDF's zero pose because 0 is outside its
    limits (a mimic follower follows its leader: none)."""
    for j in movable:
        if home[j["name"]] != 0.0 and "mimic" not in j:
            found = source.robot.joint(j["name"])
            report.assumed(
                source,
                source.robot.at if found is None else found.at,
                f"home: {home[j['name']]:.4g}, the middle of its range {j['lower']:.4g} .. "
                f"{j['upper']:.4g} (the {source.noun}'s zero pose is outside it)",
            )


def _home(joint: dict) -> float:
    """0 when inside the limits, else the middle of the range."""
    lower, upper = joint.get("lower", -math.inf), joint.get("upper", math.inf)
    return 0.0 if lower <= 0.0 <= upper else (lower + upper) / 2.0


def _deepest(root: str, joints: list[dict], frames: list[dict]) -> str | None:
    """The link or frame with the most joints above it (first in document order)."""
    depth = {root: 0}
    pending = list(joints)
    while pending:
        rest = [j for j in pending if j["parent"] not in depth]
        for joint in pending:
            if joint["parent"] in depth:
                depth[joint["child"]] = depth[joint["parent"]] + 1
        if len(rest) == len(pending):
            break
        pending = rest
    for frame in frames:
        if frame["parent"] in depth:
            depth[frame["name"]] = depth[frame["parent"]] + 1
    best = max(depth.items(), key=lambda item: item[1], default=(None, 0))
    return best[0] if best[1] > 0 else None
