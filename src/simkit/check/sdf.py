"""The SDFormat model against the URDF, both read from the kit (pure Python, no simulator).

Both files carry the same numbers through the one formatter, so they must agree to round-off:
the same links with the same mass, centre of mass and inertia (link axes); the same joints
(type, parent, child, axis, limits and dynamics) at the same place; every frame in the same
pose at seeded random configurations. libsdformat itself loads the file in tests/test_sdf.py.
"""

from __future__ import annotations

import posixpath

import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.kit import Kit
from simkit.check.readers.sdf import read_sdf
from simkit.check.readers.tree import MODEL, WORLD, Tree, TreeJoint, read_urdf
from simkit.kitio import layout

TOL = 1e-9  # both files print the same 10-significant-digit numbers (kitio/fmt.py)
MIN_VERSION = (1, 9)
CONFIGS = 10
MOVABLE = ("revolute", "continuous", "prismatic")


def check_sdf(kit: Kit) -> list[Finding]:
    file = layout.sdf(kit.name)
    if not kit.path(file).is_file():
        return [require("sdf.file", False, f"{file} is missing")]
    try:
        sdf, urdf = read_sdf(kit.path(file)), read_urdf(kit.path(kit.urdf))
        version = kit.path(file).read_text(encoding="utf-8")
    except (ValueError, TypeError, AttributeError, SyntaxError) as exc:
        return [require("sdf.parse", False, f"{file} or the URDF cannot be read: {exc}")]
    findings = [_version(file, version), _meshes(kit, file, sdf, urdf), _links(sdf, urdf)]
    findings += _inertials(sdf, urdf)
    findings += _joints(sdf, urdf)
    findings += _fk(sdf, urdf)
    return findings


def _version(file: str, text: str) -> Finding:
    import re

    found = re.search(r'<sdf[^>]*\sversion="(\d+)\.(\d+)"', text)
    got = (int(found.group(1)), int(found.group(2))) if found else (0, 0)
    return require("sdf.version", got >= MIN_VERSION, f"{file} is SDFormat {got[0]}.{got[1]}")


def _meshes(kit: Kit, file: str, sdf: Tree, urdf: Tree) -> Finding:
    """The SDF names the URDF's mesh files (relative URIs), each of which exists."""

    def resolved(owner: str, refs: list[str]) -> set[str]:
        return {posixpath.normpath(posixpath.join(posixpath.dirname(owner), r)) for r in refs}

    mine, theirs = resolved(file, sdf.meshes), resolved(kit.urdf, urdf.meshes)
    missing = sorted(p for p in mine if not kit.path(p).is_file())
    differ = sorted(mine ^ theirs)
    ok = not missing and not differ
    detail = "the SDF names the URDF's mesh files, all present"
    if not ok:
        detail = f"missing {missing[:3]}, not in both files {differ[:3]}"
    return require("sdf.meshes", ok, detail)


def _links(sdf: Tree, urdf: Tree) -> Finding:
    """Every URDF link is an SDF link, or a massless one is an SDF frame (or the world)."""
    named = set(sdf.bodies) | set(sdf.frames) | {WORLD}
    missing = sorted(set(urdf.bodies) - named)
    extra = sorted(set(sdf.bodies) - set(urdf.bodies))
    heavy = sorted(n for n in set(urdf.bodies) - set(sdf.bodies) if urdf.bodies[n].mass > 0)
    ok = not (missing or extra or heavy)
    detail = f"{len(sdf.bodies)} links and {len(sdf.frames)} frames match the URDF's links"
    if not ok:
        detail = f"not in the SDF: {missing}, not in the URDF: {extra}, heavy frames: {heavy}"
    return require("sdf.links", ok, detail)


def _inertials(sdf: Tree, urdf: Tree) -> list[Finding]:
    names = sorted(set(sdf.bodies) & set(urdf.bodies))
    a, b = [sdf.bodies[n] for n in names], [urdf.bodies[n] for n in names]
    what = f"{len(names)} links, SDF vs URDF"
    return [
        compare(
            "sdf.mass",
            f"mass of {what}",
            [x.mass for x in b],
            [x.mass for x in a],
            TOL,
            "kg",
            names,
        ),
        compare(
            "sdf.com",
            f"centre of mass of {what}",
            [x.com for x in b],
            [x.com for x in a],
            TOL,
            "m",
            names,
        ),
        compare(
            "sdf.inertia",
            f"inertia about the centre of mass of {what}",
            [x.inertia for x in b],
            [x.inertia for x in a],
            TOL,
            "kg m^2",
            names,
        ),
    ]


def _joints(sdf: Tree, urdf: Tree) -> list[Finding]:
    """The URDF's joints between SDF links: same type, ends, axis, limits and place. Joints
    pair up by child link (the SDF renames a joint whose name a link or frame has)."""
    mine = _by_child(sdf)
    wanted = [j for j in urdf.joints if j.child in sdf.bodies]
    missing = [j.name for j in wanted if j.child not in mine]
    if missing or len(sdf.joints) != len(wanted):
        extra = sorted(j.name for j in sdf.joints if j.child not in {w.child for w in wanted})
        return [require("sdf.joints", False, f"joints not in the SDF: {missing}, extra: {extra}")]
    roots = {urdf.root, WORLD} - set(sdf.bodies)
    wrong = [
        j.name
        for j in wanted
        if (mine[j.child].type, mine[j.child].child) != (j.type, j.child)
        or (
            mine[j.child].parent != j.parent
            and not {mine[j.child].parent, j.parent} <= roots | {WORLD}
        )
    ]
    shared = [(j, mine[j.child], _limit_keys(j)) for j in wanted if j.type in MOVABLE]
    at_zero_u, at_zero_s = urdf.poses({}), sdf.poses({})
    ref_u, ref_s = _reference(urdf, at_zero_u), _reference(urdf, at_zero_s)
    place_u = [ref_u @ at_zero_u[j.parent] @ j.parent_to_joint for j in wanted]
    place_s = [
        ref_s @ at_zero_s[mine[j.child].parent] @ mine[j.child].parent_to_joint for j in wanted
    ]
    return [
        require(
            "sdf.joints",
            not wrong,
            f"joint types, parents and children differ: {wrong}"
            if wrong
            else f"{len(wanted)} joints with the URDF's types, parents and children",
        ),
        compare(
            "sdf.axes",
            "joint axes (joint frame), SDF vs URDF",
            [u.axis for u, _, _ in shared],
            [s.axis for _, s, _ in shared],
            TOL,
            "",
        ),
        compare(
            "sdf.limits",
            "the URDF's joint limits and dynamics, SDF vs URDF",
            [u.limits[k] for u, _, keys in shared for k in keys],
            [s.limits.get(k, np.nan) for _, s, keys in shared for k in keys],
            TOL,
            "",
        ),
        compare("sdf.joint_poses", "joint frames at zero, SDF vs URDF", place_u, place_s, TOL, ""),
    ]


def _limit_keys(joint: TreeJoint) -> list[str]:
    """The URDF joint's limits and dynamics the SDF must repeat: all it gives, but an effort
    or velocity of 0 (simkit's URDF for "not known"; the SDF leaves those out)."""
    unknown = {k for k in ("effort", "velocity") if joint.limits.get(k) == 0}
    return sorted(set(joint.limits) - unknown)


def _by_child(tree: Tree) -> dict[str, TreeJoint]:
    return {j.child: j for j in tree.joints}


def _reference(urdf: Tree, poses: dict[str, np.ndarray]) -> np.ndarray:
    """Inverse pose of the URDF's root link in a file's poses (both then share its frame)."""
    return np.linalg.inv(poses.get(urdf.root, poses[WORLD]))


def _fk(sdf: Tree, urdf: Tree) -> list[Finding]:
    """Every link and frame, SDF vs URDF, at seeded configurations within the URDF limits."""
    rng = np.random.default_rng(0)
    movable = [j for j in urdf.joints if j.type in MOVABLE]
    mine = _by_child(sdf)
    expected, actual = [], []
    for _ in range(CONFIGS):
        q = {
            j.name: rng.uniform(j.limits.get("lower", -np.pi), j.limits.get("upper", np.pi))
            for j in movable
        }
        pu = urdf.poses(q)
        ps = sdf.poses({mine[j.child].name: q[j.name] for j in movable if j.child in mine})
        ru, rs = _reference(urdf, pu), _reference(urdf, ps)
        names = sorted(set(pu) & set(ps) - {WORLD, MODEL})
        expected += [ru @ pu[n] for n in names]
        actual += [rs @ ps[n] for n in names]
    return [
        compare(
            "sdf.fk",
            f"pose of every link and frame at {CONFIGS} random configurations, SDF vs URDF",
            np.array(expected),
            np.array(actual),
            TOL,
            "m",
        )
    ]
