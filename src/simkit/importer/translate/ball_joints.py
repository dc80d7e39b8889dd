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

from copy import deepcopy

from simkit.importer.read.source import Source
from simkit.importer.translate.geometry import floats

KIND = "spherical"
#: (name suffix, axis, PyBullet `<limit>` attribute holding that axis's half range)
AXES = (("_x", "1 0 0", "lower"), ("_y", "0 1 0", "upper"), ("", "0 0 1", "twist"))


def expand(source: Source) -> None:
    """Replace every `<joint type="spherical">` of the parsed URDF by three joints and two
    massless links, in place; one report line each (`--strict` refuses instead)."""
    balls = [j for j in source.root.findall("joint") if j.get("type") == KIND]
    if not balls:
        return
    links = {link.get("name") for link in source.root.findall("link")}
    joints = {joint.get("name") for joint in source.root.findall("joint")}
    for joint in balls:
        _expand_one(source, joint, links, joints)


def _free(name: str, taken: set) -> str:
    """`name`, or `name2`, `name3`, ... when the URDF already uses it; marked taken."""
    out, count = name, 2
    while out in taken:
        out, count = f"{name}{count}", count + 1
    taken.add(out)
    return out


def _ranges(source: Source, joint) -> tuple[float, float, float] | None:
    """PyBullet's (swing x, swing y, twist) half ranges in rad, or None: no limit."""
    limit = joint.find("limit")
    if limit is None:
        return None
    keys = ("lower", "upper", "twist", "effort")
    values = [floats(source, limit, key, 1, "0") for key in keys]
    return tuple(values[:3]) if all(v > 0 for v in values) else None  # type: ignore[return-value]


def _expand_one(source: Source, joint, links: set, joints: set) -> None:
    name = joint.get("name") or ""
    parent, child = joint.find("parent"), joint.find("child")
    if parent is None or child is None or not parent.get("link") or not child.get("link"):
        raise source.fail(joint, "a joint needs <parent link=...> and <child link=...>")
    for end in (parent, child):
        if end.get("link") not in links:
            raise source.fail(joint, f"unknown {end.tag} link '{end.get('link')}'")
    ranges = _ranges(source, joint)
    names = [_free(f"{name}{suffix}", joints) if suffix else name for suffix, _, _ in AXES]
    bodies = [_free(f"{n}_link", links) for n in names[:2]]
    if ranges is None:
        how = "continuous (no <limit> with lower, upper, twist and effort all > 0: PyBullet "
        how += "leaves the ball free)"
    else:
        how = "revolute, limits +-{:g}, +-{:g}, +-{:g} rad (PyBullet's swing x = lower, swing "
        how = (how + "y = upper, twist = twist)").format(*ranges)
    source.lenient(
        joint,
        f"spherical joint {name}: three revolute joints {', '.join(names)} about the joint "
        f"frame's x, y, z axes through massless links {', '.join(bodies)}; {how}",
    )
    ends = [parent.get("link"), *bodies, child.get("link")]
    built = [_joint(joint, n, ends[i], ends[i + 1], AXES[i], ranges) for i, n in enumerate(names)]
    for element in built[:2]:
        joint.addprevious(element)
    _retype(joint, built[2])
    anchor = next(x for x in source.root.findall("link") if x.get("name") == ends[-1])
    for body in bodies:  # before the child link: the chain keeps its place among siblings
        link = anchor.makeelement("link", {"name": body})
        _keep_line(link, joint)
        anchor.addprevious(link)


def _joint(ball, name: str, parent: str, child: str, axis: tuple, ranges) -> object:
    """One joint of the chain: the first takes the ball's `<origin>`, all its `<limit>`
    effort and velocity and its `<dynamics>`."""
    _, xyz, key = axis
    kind = "continuous" if ranges is None else "revolute"
    out = ball.makeelement("joint", {"name": name, "type": kind})
    _keep_line(out, ball)
    for tag, attrs in (("parent", {"link": parent}), ("child", {"link": child})):
        out.append(out.makeelement(tag, attrs))
    origin = ball.find("origin")
    if origin is not None and parent == ball.find("parent").get("link"):
        out.append(_copy(origin))
    out.append(out.makeelement("axis", {"xyz": xyz}))
    limit = ball.find("limit")
    if limit is not None:
        attrs = {k: limit.get(k) for k in ("effort", "velocity") if limit.get(k) is not None}
        if ranges is not None:
            half = f"{ranges[[a[2] for a in AXES].index(key)]!r}"
            attrs.update(lower=f"-{half}", upper=half)
        element = out.makeelement("limit", attrs)
        _keep_line(element, limit)
        out.append(element)
    dynamics = ball.find("dynamics")
    if dynamics is not None:
        out.append(_copy(dynamics))
    return out


def _keep_line(element, origin) -> None:
    """`element` takes `origin`'s source line, where it has one (an MJCF's tree, built from
    the compiled model, has none)."""
    if origin.sourceline is not None:
        element.sourceline = origin.sourceline


def _copy(element):
    """A copy of an element that keeps its source line (for report lines)."""
    out = deepcopy(element)
    _keep_line(out, element)
    return out


def _retype(ball, last) -> None:
    """The URDF's own joint element becomes the chain's last joint (its line, its name and
    any other child element stay, so the usual rules report them)."""
    for tag in ("parent", "origin", "axis", "limit"):
        for element in ball.findall(tag):
            ball.remove(element)
    ball.set("type", last.get("type"))
    for element in reversed([e for e in last if e.tag in ("parent", "axis", "limit")]):
        ball.insert(0, element)
