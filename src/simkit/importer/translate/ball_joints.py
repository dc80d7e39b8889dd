"""URDF `spherical` joints (PyBullet's ball joint) as three revolute joints (issue 22).

The spec has one-degree-of-freedom joints only, so a ball joint becomes what the field
writes where a format has none: a chain of three joints about the joint frame's x, y and z
axes, through two massless, geometry-free links, i.e. the rotation Rx(a) Ry(b) Rz(c)
(intrinsic x-y-z Euler angles). The rewrite happens on the parsed URDF before translation,
so the new joints and links take every rule of an ordinary URDF joint and link (effort,
velocity and armature estimates, the small mass of a massless link), each reported at the
spherical joint's line.

Names: the URDF joint `NAME` keeps its name on the last joint (the one carrying the child
link); the others are `NAME_x`, `NAME_y`, between links `NAME_x_link` and `NAME_y_link`
(a numeric suffix where the URDF already uses such a name).

Limits, as PyBullet reads them (URDF2Bullet.cpp, btMultiBodySphericalJointLimit): a
`<limit lower=SX upper=SY twist=T effort=E>` limits the swing about x to +-SX, the swing
about y to +-SY and the twist about z to +-T, and only when all four are > 0; otherwise the
ball turns freely. So the three joints are revolute with +-SX, +-SY, +-T, or all continuous.
PyBullet ignores a spherical joint's `<axis>`; so does the import.
"""

from __future__ import annotations

from dataclasses import replace

from simkit.importer.read.model import At, Joint, Limit, Link, Pose
from simkit.importer.read.source import Source

KIND = "spherical"
#: (name suffix, axis, PyBullet `<limit>` attribute holding that axis's half range)
AXES = (
    ("_x", (1.0, 0.0, 0.0), "lower"),
    ("_y", (0.0, 1.0, 0.0), "upper"),
    ("", (0.0, 0.0, 1.0), "twist"),
)


def expand(source: Source) -> None:
    """Replace every spherical joint of the source model by three joints and two massless
    links (`source.robot` replaced); one report line each (`--strict` refuses instead)."""
    robot = source.robot
    balls = [j for j in robot.joints if j.type == KIND]
    if not balls:
        return
    links = {link.name for link in robot.links}
    joints = {joint.name for joint in robot.joints}
    new_joints: list[Joint] = []
    added: dict[str, list[Link]] = {}  # child link name -> the chain's links before it
    for joint in robot.joints:
        if joint.type != KIND:
            new_joints.append(joint)
            continue
        chain, bodies = _expand_one(source, joint, links, joints)
        new_joints.extend(chain)
        added.setdefault(joint.child, []).extend(bodies)
    new_links: list[Link] = []
    for link in robot.links:  # before the child link: the chain keeps its place among siblings
        if link.name in added:
            new_links.extend(added.pop(link.name))
        new_links.append(link)
    source.robot = replace(robot, links=tuple(new_links), joints=tuple(new_joints))


def _free(name: str, taken: set) -> str:
    """`name`, or `name2`, `name3`, ... when the URDF already uses it; marked taken."""
    out, count = name, 2
    while out in taken:
        out, count = f"{name}{count}", count + 1
    taken.add(out)
    return out


def _ranges(joint: Joint) -> tuple[float, float, float] | None:
    """PyBullet's (swing x, swing y, twist) half ranges in rad, or None: no limit."""
    limit = joint.limit
    if limit is None:
        return None
    values = [v or 0.0 for v in (limit.lower, limit.upper, limit.twist, limit.effort)]
    return tuple(values[:3]) if all(v > 0 for v in values) else None  # type: ignore[return-value]


def _expand_one(source: Source, joint: Joint, links: set, joints: set):
    """The three joints (the last keeps the ball's name and line) and the two links."""
    name = joint.name or ""
    if not joint.parent or not joint.child:
        raise source.fail(joint.at, "a joint needs <parent link=...> and <child link=...>")
    for end, link in (("parent", joint.parent), ("child", joint.child)):
        if link not in links:
            raise source.fail(joint.at, f"unknown {end} link '{link}'")
    ranges = _ranges(joint)
    names = [_free(f"{name}{suffix}", joints) if suffix else name for suffix, _, _ in AXES]
    bodies = [_free(f"{n}_link", links) for n in names[:2]]
    if ranges is None:
        how = "continuous (no <limit> with lower, upper, twist and effort all > 0: PyBullet "
        how += "leaves the ball free)"
    else:
        how = "revolute, limits +-{:g}, +-{:g}, +-{:g} rad (PyBullet's swing x = lower, swing "
        how = (how + "y = upper, twist = twist)").format(*ranges)
    source.lenient(
        joint.at,
        f"spherical joint {name}: three revolute joints {', '.join(names)} about the joint "
        f"frame's x, y, z axes through massless links {', '.join(bodies)}; {how}",
    )
    ends = [joint.parent, *bodies, joint.child]
    chain = [_joint(joint, n, ends[i], ends[i + 1], AXES[i], ranges) for i, n in enumerate(names)]
    line = joint.at.sourceline
    return chain, [Link(body, At("link", body, line)) for body in bodies]


def _joint(ball: Joint, name: str, parent: str, child: str, axis: tuple, ranges) -> Joint:
    """One joint of the chain: the first takes the ball's origin, all its `<limit>` effort
    and velocity and its `<dynamics>`; the last is the ball's own element (its line, its
    name and any other child element stay, so the usual rules report them)."""
    _, xyz, key = axis
    kind = "continuous" if ranges is None else "revolute"
    last = name == ball.name and child == ball.child
    at = ball.at if last else At("joint", name, ball.at.sourceline)
    limit = None
    if ball.limit is not None:
        half = None if ranges is None else ranges[[a[2] for a in AXES].index(key)]
        lower, upper = (None, None) if half is None else (-half, half)
        if kind == "continuous":
            lower = upper = None
        limit = Limit(ball.limit.at, lower, upper, ball.limit.effort, ball.limit.velocity)
    return Joint(
        name,
        kind,
        at,
        parent,
        child,
        ball.origin if parent == ball.parent else Pose(),
        xyz,
        ball.axis_at if last else None,
        limit,
        ball.dynamics,
        ball.mimic if last else None,
        ball.unknown if last else (),
    )
