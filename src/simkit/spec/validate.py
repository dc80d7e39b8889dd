"""Load a spec file and validate it: schema first (pydantic), then cross-references.

All problems of a stage are collected and reported in file order, each on its own line
`FILE:LINE: field: message` at the line of its key (up to `MAX_LISTED`), as yourdfpy's
validation collects them; a single problem is one line.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
from pydantic import ValidationError

from simkit.errors import SpecError
from simkit.spec import bounds as spec_bounds
from simkit.spec import loops as spec_loops
from simkit.spec import mjcf as spec_mjcf
from simkit.spec import names as spec_names
from simkit.spec import sim as spec_sim
from simkit.spec import urdf_blocks as spec_urdf_blocks
from simkit.spec.load import Loc, SourceDoc, dotted, load_yaml
from simkit.spec.schema import InertiaSpec, RobotSpec, depth_first
from simkit.spec.suggest import did_you_mean

Problem = tuple[Loc, str]

ESTIMABLE_ROBOT = {"payload", "repeatability_mm", "mass", "reach_wrist", "reach_flange"}


def inertia_problem(inertia: InertiaSpec) -> str | None:
    """Why an inertia tensor is not physical (not symmetric positive definite, or breaks the
    triangle inequality of principal moments), or None."""
    tensor = np.array(
        [
            [inertia.ixx, inertia.ixy, inertia.ixz],
            [inertia.ixy, inertia.iyy, inertia.iyz],
            [inertia.ixz, inertia.iyz, inertia.izz],
        ]
    )
    eig = np.linalg.eigvalsh(tensor)
    if eig.min() <= 0:
        return f"inertia is not positive definite (principal moments {_fmt3(eig)} kg m^2)"
    a, b, c = sorted(eig)
    if a + b < c * (1 - 1e-9):
        return (
            f"inertia breaks the triangle inequality: principal moments {_fmt3(eig)} kg m^2, "
            f"{a:.6g} + {b:.6g} < {c:.6g}"
        )
    if mujoco_refuses(inertia):
        return (
            f"inertia is on the triangle-inequality limit: principal moments {_fmt3(eig)} kg "
            f"m^2, {a:.6g} + {b:.6g} = {c:.6g}, which MuJoCo refuses after rounding"
        )
    return None


#: relative margin for a full tensor: numpy's and MuJoCo's eigenvalues differ by round-off
#: (a few ulps), so a tensor on the limit within this is refused rather than left to chance
EIG_MARGIN = 1e-12


def mujoco_refuses(inertia: InertiaSpec) -> bool:
    """Whether MuJoCo's compiler would refuse the tensor as the kit writes it (kitio/fmt.py's
    10 digits): it tests A + B >= C on the principal moments with no tolerance. A diagonal
    tensor's moments are its diagonal, tested here exactly as MuJoCo does; a full one's are
    eigenvalues, tested with EIG_MARGIN."""
    from simkit.kitio.fmt import num

    values = [
        float(num(v))
        for v in (inertia.ixx, inertia.iyy, inertia.izz, inertia.ixy, inertia.ixz, inertia.iyz)
    ]
    x, y, z = values[:3]
    if not any(values[3:]):
        return x + y < z or x + z < y or y + z < x
    tensor = np.array(
        [[x, values[3], values[4]], [values[3], y, values[5]], [values[4], values[5], z]]
    )
    a, b, c = sorted(np.linalg.eigvalsh(tensor))
    return bool(a + b < c * (1 + EIG_MARGIN))


def _fmt3(values: np.ndarray) -> str:
    return "(" + ", ".join(f"{v:.6g}" for v in values) + ")"


def _cross_reference(spec: RobotSpec) -> Iterator[Problem]:
    yield from spec_names.problems(spec)
    yield from spec_bounds.problems(spec)
    links = {link.name: i for i, link in enumerate(spec.links)}
    materials = {m.name for m in spec.materials}
    names_seen: dict[str, Loc] = {spec.root: ("root",)}
    for kind, items in (("links", spec.links), ("joints", spec.joints), ("frames", spec.frames)):
        for i, item in enumerate(items):
            if kind != "joints" and item.name in names_seen:
                yield (kind, i, "name"), f"name '{item.name}' is already used"
            names_seen.setdefault(item.name, (kind, i, "name"))
    joint_names: set[str] = set()
    for i, joint in enumerate(spec.joints):
        if joint.name in joint_names:
            yield ("joints", i, "name"), f"joint name '{joint.name}' is already used"
        joint_names.add(joint.name)

    for i, link in enumerate(spec.links):
        if link.material is not None and link.material not in materials:
            yield ("links", i, "material"), f"unknown material '{link.material}'"
        if link.inertia is not None:
            why = inertia_problem(link.inertia)
            if why and link.inertia_decision is None:
                yield ("links", i, "inertia"), why + " (fix it, or record an inertia_decision)"
        if link.inertia is not None and link.com is None:
            yield ("links", i, "com"), "a link that gives its inertia must give its com too"
        if link.collision == "given" and not link.collision_shapes:
            yield ("links", i, "collision_shapes"), "'given' collision needs collision_shapes"
        if not link.solid and link.collision != "primitives":
            yield ("links", i, "solid"), "a link needs a solid (its visual geometry)"
        elif not link.solid and link.inertia is None:
            why = "a link without a solid needs inertia and com (nothing to derive them from)"
            yield ("links", i, "solid"), why
        if link.collision == "convex" and any(p.subtract or p.shape == "mesh" for p in link.solid):
            yield (
                ("links", i, "collision"),
                (
                    "'convex' needs a union of convex primitives (no mesh, no subtract); "
                    "use 'auto' or 'coacd'"
                ),
            )
        allowed = set(type(link).model_fields) - {"name", "estimated", "note"}
        for k, field in enumerate(link.estimated):
            if field not in allowed:
                yield ("links", i, "estimated", k), f"'{field}' is not a field of a link"

    children: dict[str, int] = {}
    for i, joint in enumerate(spec.joints):
        if joint.parent != spec.root and joint.parent not in links:
            yield ("joints", i, "parent"), f"unknown parent link '{joint.parent}'"
        if joint.child not in links:
            yield ("joints", i, "child"), f"unknown child link '{joint.child}'"
        elif joint.child in children:
            yield ("joints", i, "child"), f"link '{joint.child}' already has a parent joint"
        children.setdefault(joint.child, i)
        lower = joint.lower if joint.lower is not None else joint.lower_deg
        upper = joint.upper if joint.upper is not None else joint.upper_deg
        if lower is not None and upper is not None and lower > upper:
            field = "lower" if joint.lower is not None else "lower_deg"
            yield ("joints", i, field), f"lower ({lower}) is greater than upper ({upper})"
        if joint.type in ("revolute", "prismatic") and (lower is None or upper is None):
            yield ("joints", i, "type"), f"a {joint.type} joint needs lower and upper limits"
        peak, continuous = joint.effort_peak, joint.effort_continuous
        if peak is not None and continuous is not None and continuous > peak:
            yield (
                ("joints", i, "effort_continuous"),
                f"effort_continuous ({continuous:g}) is greater than effort_peak ({peak:g})",
            )
        if joint.mimic is not None:
            leader = next((j for j in spec.joints if j.name == joint.mimic.joint), None)
            if leader is None or leader.type in ("fixed", "floating") or leader is joint:
                yield (
                    ("joints", i, "mimic", "joint"),
                    f"mimic needs another movable joint, not '{joint.mimic.joint}'",
                )
        allowed = set(type(joint).model_fields) - {"name", "estimated"}
        for k, field in enumerate(joint.estimated):
            if field not in allowed:
                yield ("joints", i, "estimated", k), f"'{field}' is not a field of a joint"
        if joint.drive is not None:
            allowed = set(type(joint.drive).model_fields) - {"estimated"}
            for k, field in enumerate(joint.drive.estimated):
                if field not in allowed:
                    loc = ("joints", i, "drive", "estimated", k)
                    yield loc, f"'{field}' is not a field of a drive"
    for i, link in enumerate(spec.links):
        if link.name not in children:
            yield ("links", i, "name"), f"link '{link.name}' is not the child of any joint"
    for i, frame in enumerate(spec.frames):
        if frame.parent != spec.root and frame.parent not in links:
            yield ("frames", i, "parent"), f"unknown parent link '{frame.parent}'"
    yield from _cycles(spec)
    yield from _floating(spec)
    yield from spec_mjcf.problems(spec, set(links), {f.name for f in spec.frames})
    yield from spec_sim.problems(spec, inertia_problem)
    frames = {f.name for f in spec.frames}
    yield from spec_urdf_blocks.problems(
        spec,
        {spec.root, *links, *frames},
        {j.name for j in spec.joints} | {f.joint or f"{f.name}_joint" for f in spec.frames},
    )

    movable = [j for j in spec.joints if j.type not in ("fixed", "floating")]
    for key in ("poses", "poses_deg"):
        for pose, values in getattr(spec, key).items():
            if len(values) != len(movable):
                yield (
                    (key, pose),
                    (f"pose '{pose}' has {len(values)} values for {len(movable)} movable joints"),
                )
    for pose in sorted(set(spec.poses) & set(spec.poses_deg)):
        yield ("poses_deg", pose), f"pose '{pose}' is given in both poses and poses_deg"
    for key in ("wrist_centre", "tool_frame"):
        value = getattr(spec, key)
        if value is not None and value not in names_seen:
            yield (key,), f"unknown link or frame '{value}'"
    yield from _planning_groups(spec)
    yield from _contact_excludes(spec)
    yield from spec_loops.problems(spec)
    for k, field in enumerate(spec.published.estimated):
        if field not in ESTIMABLE_ROBOT:
            yield ("published", "estimated", k), f"'{field}' is not a published figure"


def _planning_groups(spec: RobotSpec) -> Iterator[Problem]:
    """Each planning group's tip must be a link or frame below its base link (SRDF chain)."""
    parent = {j.child: j.parent for j in spec.joints}
    parent.update({f.name: f.parent for f in spec.frames})
    names: set[str] = set()
    for i, group in enumerate(spec.planning_groups):
        if group.name in names:
            yield ("planning_groups", i, "name"), f"group name '{group.name}' is already used"
        names.add(group.name)
        if group.base != spec.root and group.base not in {link.name for link in spec.links}:
            yield ("planning_groups", i, "base"), f"unknown link '{group.base}'"
            continue
        node, seen = group.tip, set()
        while node != group.base and node in parent and node not in seen:
            seen.add(node)
            node = parent[node]
        if node != group.base:
            why = f"'{group.tip}' is not a link or frame below '{group.base}'"
            yield ("planning_groups", i, "tip"), why


def _contact_excludes(spec: RobotSpec) -> Iterator[Problem]:
    """Each excluded pair names two different links, not joined by a joint (a kit excludes
    those already), and only once."""
    links = {link.name for link in spec.links}
    jointed = {frozenset((j.parent, j.child)) for j in spec.joints}
    seen: set[frozenset] = set()
    for i, (a, b) in enumerate(spec.contact_excludes):
        pair = frozenset((a, b))
        unknown = [n for n in (a, b) if n not in links]
        if unknown:
            yield ("contact_excludes", i), f"unknown link '{unknown[0]}'"
        elif a == b:
            yield ("contact_excludes", i), f"a link cannot be excluded from itself ('{a}')"
        elif pair in jointed:
            why = f"'{a}' and '{b}' are joined by a joint: excluded already"
            yield ("contact_excludes", i), why
        elif pair in seen:
            yield ("contact_excludes", i), f"the pair '{a}', '{b}' is listed twice"
        seen.add(pair)


def _floating(spec: RobotSpec) -> Iterator[Problem]:
    """A floating base is one `floating` joint from the root (the world) to the base link; the
    URDF starts at that link, so nothing else may hang on the root."""
    floating = [i for i, j in enumerate(spec.joints) if j.type == "floating"]
    for i in floating[1:]:
        yield ("joints", i, "type"), "only one joint may be floating"
    for i in floating:
        joint = spec.joints[i]
        if joint.parent != spec.root:
            yield ("joints", i, "parent"), f"a floating joint must hang on the root '{spec.root}'"
        for key in ("lower", "upper", "lower_deg", "upper_deg"):
            if getattr(joint, key) is not None:
                yield ("joints", i, key), "a floating joint has no limits"
    if spec.floating_base and not floating:
        yield ("floating_base",), "floating_base needs a joint of type 'floating' from the root"
    if floating:
        for i, joint in enumerate(spec.joints):
            if joint.parent == spec.root and joint.type != "floating":
                yield ("joints", i, "parent"), "with a floating base only it may hang on the root"
        for i, frame in enumerate(spec.frames):
            if frame.parent == spec.root:
                yield ("frames", i, "parent"), "with a floating base frames go on links"


def _cycles(spec: RobotSpec) -> Iterator[Problem]:
    parent_of = {j.child: (j.parent, i) for i, j in enumerate(spec.joints)}
    rooted: set[str] = set()  # links whose walk up reached a root: linear in a long chain
    for start in parent_of:
        seen = {start}
        node = start
        while node in parent_of and node not in rooted:
            node, index = parent_of[node]
            if node in seen:
                yield ("joints", index, "parent"), f"joints form a loop through '{node}'"
                return
            seen.add(node)
        rooted |= seen


#: spec problems listed, one per line, before "(and N more errors not shown)"
MAX_LISTED = 20


def _first(problems: list[Problem], doc: SourceDoc) -> SpecError:
    """Every problem in file order (up to `MAX_LISTED`), each at the line of its key, as one
    `SpecError`: the first is its head, the rest its `others`."""
    located = sorted(
        ((doc.line_of(loc) or 0, i, loc, msg) for i, (loc, msg) in enumerate(problems)),
        key=lambda item: (item[0], item[1]),
    )
    listed = [(line or None, dotted(loc), msg) for line, _, loc, msg in located[:MAX_LISTED]]
    (line, field, msg), others = listed[0], tuple(listed[1:])
    more = max(0, len(located) - MAX_LISTED)
    return SpecError(doc.file, line, field, msg, more=more, others=others)


def _pydantic_problems(exc: ValidationError) -> list[Problem]:
    problems: list[Problem] = []
    for err in exc.errors(include_url=False):
        loc = tuple(part for part in err["loc"] if not str(part).startswith("function-"))
        msg = err["msg"].removeprefix("Value error, ")
        if err["type"] == "extra_forbidden":
            msg = "unknown field" + did_you_mean(RobotSpec, loc)
        elif err["type"] == "missing":
            msg = "required field is missing"
        problems.append((loc, msg))
    return problems


def validate(doc: SourceDoc) -> RobotSpec:
    """Validate a loaded document into a `RobotSpec`, or raise the first `SpecError`."""
    if not isinstance(doc.data, dict):
        raise SpecError(doc.file, 1, "<root>", "the spec must be a mapping of fields")
    try:
        spec = RobotSpec.model_validate(doc.data)
    except ValidationError as exc:
        raise _first(_pydantic_problems(exc), doc) from None
    problems = list(_cross_reference(spec))
    if not problems:  # the joint tree is sound: poses can be read in the model's joint order
        problems = list(_pose_limits(spec))
    if problems:
        raise _first(problems, doc)
    return spec


def _pose_limits(spec: RobotSpec) -> Iterator[Problem]:
    """Every named pose lies within the joint limits and keeps each loop closed
    (spec/loops.py). Pose values follow the model's joint order (depth-first,
    `resolve.py`), as `Robot.pose` reads them."""
    yield from spec_loops.pose_problems(spec, depth_first(spec.joints, spec.root))
    joints = [j for j in depth_first(spec.joints, spec.root) if j.movable]
    for key, scale in (("poses", 1.0), ("poses_deg", math.pi / 180)):
        for pose, values in getattr(spec, key).items():
            for k, (joint, value) in enumerate(zip(joints, values, strict=True)):
                lower, upper = joint.limits()
                if joint.type == "continuous" or lower is None or upper is None:
                    continue
                q = value * scale
                if not lower - 1e-9 <= q <= upper + 1e-9:
                    yield (
                        (key, pose, k),
                        f"pose '{pose}' puts {joint.name} at {value:g}"
                        f"{' deg' if scale != 1.0 else ''}, outside its limits",
                    )


def _mesh_files(spec: RobotSpec, base_dir: Path) -> Iterator[Problem]:
    """Mesh primitives name files (relative to the spec) that exist."""
    for i, link in enumerate(spec.links):
        for k, prim in enumerate(link.solid):
            if prim.shape == "mesh" and prim.file and not (base_dir / prim.file).is_file():
                yield ("links", i, "solid", k, "file"), f"mesh file not found: {prim.file}"


def _source_file(spec: RobotSpec, base_dir: Path) -> Iterator[Problem]:
    """An imported spec's kept source (`source.file`, beside the spec) exists."""
    if spec.source is not None and not (base_dir / spec.source.file).is_file():
        yield ("source", "file"), f"source file not found: {spec.source.file}"


def load_spec(path: Path, display: str | None = None) -> tuple[RobotSpec, SourceDoc]:
    """Read and validate one spec file."""
    doc = load_yaml(path, display)
    spec = validate(doc)
    problems = list(_mesh_files(spec, path.parent)) + list(_source_file(spec, path.parent))
    if problems:
        raise _first(problems, doc)
    return spec, doc
