"""One name grammar for everything a spec names, and the names the emitters generate from them.

Names become file names (`meshes/visual/NAME.stl`), XML attributes, USD prim paths, Python
string literals, YAML keys and ROS parameter names. So a name is an identifier,
`[A-Za-z_][A-Za-z0-9_]*` of at most `MAX_NAME` characters: it can be neither a path (`..`, `/`)
nor syntax in any of those languages. On top of the grammar, a name may not equal a name the
emitters derive from another one (`tool0` -> URDF joint `tool0_joint`), and two names may
not differ only by case (they would share a file on a case-insensitive file system).
"""

from __future__ import annotations

import re
from collections.abc import Iterator

from simkit.spec.load import Loc

Problem = tuple[Loc, str]

MAX_NAME = 64
#: Robot names are also the ROS 2 package (`NAME_description`) and file stems: lower case.
MAX_ROBOT_NAME = 48
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
ROBOT_NAME = re.compile(r"[a-z][a-z0-9_]*")
#: A frame's `joint` appears in the kit's URDF alone (an XML attribute): URDF names such as
#: `wrist_3_link-tool0_fixed_joint` are kept as they are.
URDF_ONLY_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-]*")

#: Names some emitter writes itself (SRDF virtual joint, ros2_control broadcaster, MJCF world).
RESERVED = frozenset({"world", "virtual_joint", "joint_state_broadcaster"})

#: Suffixes an emitter appends to a link, joint or frame name (emit/urdf.py, emit/mjcf.py,
#: emit/ros2_control.py, collision_pairs.py). `#` stands for a two-digit piece index.
GENERATED_SUFFIXES = {
    "links": ("_visual", "_collision_#", "_#"),
    "joints": (
        "_transmission",
        "_actuator",
        "_position_controller",
        "_effort_controller",
        "_locked",
    ),
    "frames": ("_joint",),
}


def name_problem(value: object, robot: bool = False, urdf_only: bool = False) -> str | None:
    """Why `value` is not a valid name, or None (`urdf_only`: a name only the kit's URDF
    writes, which may also hold `.` and `-`)."""
    grammar, cap = (ROBOT_NAME, MAX_ROBOT_NAME) if robot else (NAME, MAX_NAME)
    grammar = URDF_ONLY_NAME if urdf_only and not robot else grammar
    if not isinstance(value, str):
        return f"a name must be a string, got {type(value).__name__}"
    if not value:
        return "a name must not be empty"
    if len(value) > cap:
        return f"a name has at most {cap} characters (this one has {len(value)})"
    if not grammar.fullmatch(value):
        allowed = "a-z, 0-9 and _ (starting with a letter)" if robot else "A-Z, a-z, 0-9 and _"
        allowed += ", . and -" if urdf_only else ""
        shown = value if value.isprintable() else repr(value)
        return f"invalid name '{shown}': use only {allowed}, not starting with a digit"
    return None


def _named(spec) -> Iterator[tuple[str, Loc, str]]:
    """(kind, location, name) of every name a spec defines."""
    yield "root", ("root",), spec.root
    for kind in ("links", "joints", "frames", "materials", "planning_groups"):
        for i, item in enumerate(getattr(spec, kind)):
            yield kind, (kind, i, "name"), item.name
    for i, frame in enumerate(spec.frames):  # a frame's own URDF joint name
        if getattr(frame, "joint", None) is not None:
            yield "frame_joint", ("frames", i, "joint"), frame.joint
    for key in ("poses", "poses_deg"):
        for pose in getattr(spec, key):
            yield "poses", (key, pose), pose
    if spec.mjcf is not None:
        for kind in ("defaults", "textures", "materials", "lights", "cameras", "sensors"):
            for i, item in enumerate(getattr(spec.mjcf, kind)):
                if item.name is not None:
                    yield f"mjcf.{kind}", ("mjcf", kind, i, "name"), item.name
        if spec.mjcf.floor is not None:
            yield "mjcf.floor", ("mjcf", "floor", "name"), spec.mjcf.floor.name
    if spec.freefall is not None:
        yield "ref", ("freefall", "pose"), spec.freefall.pose
    for key in ("wrist_centre", "tool_frame"):
        if getattr(spec, key) is not None:
            yield "ref", (key,), getattr(spec, key)


def _generated(spec) -> dict[str, str]:
    """Lower-cased generated name -> what it is generated from (regex suffixes as patterns)."""
    out: dict[str, str] = {}
    for kind, suffixes in GENERATED_SUFFIXES.items():
        for item in getattr(spec, kind):
            if getattr(item, "joint", None) is not None:  # a frame naming its own joint
                continue
            for suffix in suffixes:
                if "#" not in suffix:
                    out[(item.name + suffix).lower()] = f"{kind[:-1]} '{item.name}'"
    return out


def _piece_owner(name: str, links: set[str]) -> str | None:
    """The link whose generated collision-piece name `name` is (`L_collision_03`, `L_03`)."""
    match = re.fullmatch(r"(.+?)(?:_collision)?_\d{2,}", name.lower())
    return match.group(1) if match and match.group(1) in links else None


def problems(spec) -> Iterator[Problem]:
    """Every name that breaks the grammar, is reserved, collides with a generated name, or
    differs from another only by case."""
    why = name_problem(spec.name, robot=True)
    if why:
        yield ("name",), why
    named = list(_named(spec))
    bad = False
    for kind, loc, value in named:
        why = name_problem(value, urdf_only=kind == "frame_joint")
        if why:
            bad = True
            yield loc, why
    if bad:
        return
    generated = _generated(spec)
    links = {link.name.lower() for link in spec.links}
    firsts: dict[tuple[str, str], tuple[str, Loc]] = {}
    for kind, loc, value in named:
        if kind == "ref":
            continue
        low = value.lower()
        if low in RESERVED and kind in ("links", "joints", "frames", "frame_joint"):
            yield loc, f"'{value}' is a name simkit writes itself; choose another"
            continue
        if kind in ("links", "joints", "frames", "root", "frame_joint"):
            if low in generated:
                yield loc, f"'{value}' is the name simkit generates for {generated[low]}"
                continue
            owner = _piece_owner(value, links)
            if owner is not None:
                yield loc, f"'{value}' is the name simkit generates for a piece of link '{owner}'"
                continue
        space = "tree" if kind in ("links", "joints", "frames", "root", "frame_joint") else kind
        seen = firsts.setdefault((space, low), (value, loc))
        if seen[0] != value:
            yield loc, f"'{value}' differs from '{seen[0]}' only by case; names must differ"
