"""geometry.connected: at home, each link's solid meets its parent's across their joint.

A joint moved in the spec without the solids that follow it (a longer upper arm whose drive
and tube stay where they were) leaves a link floating in the air; the published numbers or
the FK checks cannot see it, since they follow the joints, not the shapes. This check reads
the written files only: robot.json's joints and home pose, and each link's visual STL
(`meshes/visual/LINK.stl`, link frame, metres).

Each solid is sampled at its vertices, face centroids and edge midpoints (at most
`MAX_POINTS`). A quick upper bound on the gap comes first: the nearest pair of samples, one
from each solid (a k-d tree). Only a pair that this cannot clear is measured closely: the
samples of each solid against the other's surface by trimesh's signed distance; a sample
inside (or on) the other solid makes the gap 0, else the gap is the smaller of the two
nearest distances (still an upper bound, tight to a fraction of a facet).

`CONNECTED_TOL` was measured on the five seed robots (asimov, ecn_2r, rosie_600, rosie_1000,
rosie_1400) with `python scripts/measure_connected.py build/*_description` (after `simkit
build` of each; exact gaps): the solids at a joint overlap or keep a running clearance between
a drive and its output, at most 5 mm (asimov's toe, 5.0 mm; the Rosies' J4, 4 mm; ecn_2r 0).
The small hand-written specs of the test suite keep wider ones by design: 10 mm under
planar_2r's first link, 20 mm at collision_mix's hub and under test_drake_hull's arm. The
tolerance, 25 mm, clears all of these; the 150 mm longer upper arm of rosie_600 (J3 moved,
its solids not) leaves 39 mm, and a link left behind by a longer move leaves more
(docs/maintaining.md).

For an imported spec (robot.json carries `source`), whose meshes may float by design (a
cosmetic shell, a sensor on a bracket that is not modelled), the check reports the gaps and
never fails.
"""

from __future__ import annotations

import numpy as np

from simkit.check.findings import Finding
from simkit.check.kit import Kit
from simkit.kitio.fmt import num
from simkit.kitio.stl import StlMesh, from_stl
from simkit.model.kinematics import axis_angle, rpy_matrix, transform

#: m: the largest gap at home between a link's solid and its parent's (measured: at most 5 mm
#: on the seed robots, 20 mm on the test suite's specs; see the module docstring)
CONNECTED_TOL = 0.025
#: points sampled per solid per side (vertices, face centroids, edge midpoints, evenly thinned)
MAX_POINTS = 4000


def home_poses(kit: Kit) -> dict[str, np.ndarray]:
    """T_root_link (4x4) of every link at robot.json's home pose (zeros without one), walking
    its joints (movable and fixed) from the root, as `Kit.fk` composes them."""
    joints = kit.joints + kit.doc.get("fixed_joints", [])
    home = kit.doc.get("home") or [0.0] * len(kit.joints)
    values = dict(zip([j["name"] for j in kit.joints], home, strict=True))
    by_parent: dict[str, list[dict]] = {}
    for joint in joints:
        by_parent.setdefault(joint["parent"], []).append(joint)
    children = {j["child"] for j in joints}
    poses = {root: np.eye(4) for root in sorted(set(by_parent) - children)}
    stack = sorted(poses)
    while stack:
        parent = stack.pop()
        for joint in by_parent.get(parent, []):
            out = poses[parent] @ transform(joint["origin_xyz"], rpy_matrix(joint["origin_rpy"]))
            q = values.get(joint["name"], 0.0)
            if joint.get("type") == "prismatic":
                out = out @ transform(np.asarray(joint["axis"]) * q)
            elif joint["name"] in values:
                out = out @ transform((0, 0, 0), axis_angle(joint["axis"], q))
            poses[joint["child"]] = out
            stack.append(joint["child"])
    return poses


def _points(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Vertices, face centroids and edge midpoints, thinned evenly to `MAX_POINTS`."""
    tri = vertices[faces]
    mids = (tri + np.roll(tri, 1, axis=1)) / 2.0
    points = np.concatenate([vertices, tri.mean(axis=1), mids.reshape(-1, 3)])
    if len(points) > MAX_POINTS:
        points = points[np.linspace(0, len(points) - 1, MAX_POINTS).astype(int)]
    return points


def point_gap(a: StlMesh, b: StlMesh) -> float:
    """An upper bound on the gap (m) between two solids: the nearest pair of their sample
    points (`_points`), by a k-d tree; quick, so the exact `solid_gap` runs only on pairs
    this cannot clear."""
    from scipy.spatial import cKDTree

    pa, pb = _points(a.vertices, a.faces), _points(b.vertices, b.faces)
    return float(cKDTree(pa).query(pb, k=1)[0].min())


def solid_gap(a: StlMesh, b: StlMesh) -> float:
    """The gap (m) between two solids (vertices, faces) in one frame: 0 when they touch or
    overlap."""
    import trimesh
    from trimesh.proximity import signed_distance

    gaps = []
    for mesh, other in ((a, b), (b, a)):
        solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
        depth = signed_distance(solid, _points(other.vertices, other.faces))
        if float(depth.max()) >= 0.0:  # positive inside: a point of `other` in `mesh`
            return 0.0
        gaps.append(-float(depth.max()))
    return min(gaps)


def joint_gaps(kit: Kit, clear: float = 0.0) -> list[tuple[str, str, str, float]]:
    """(joint, parent link, child link, gap in m) at home for every joint whose two links
    both have a solid, in robot.json's joint order (movable, then fixed). A pair whose
    `point_gap` is at most `clear` gets that bound instead of the exact gap (the check needs
    only to know it is within its tolerance)."""
    files = {link["name"]: (link.get("mesh") or {}).get("visual") for link in kit.doc["links"]}
    poses = home_poses(kit)
    solids: dict[str, StlMesh] = {}

    def solid(name: str) -> StlMesh:
        if name not in solids:
            mesh = from_stl(kit.path(files[name]).read_bytes())
            placed = mesh.vertices @ poses[name][:3, :3].T + poses[name][:3, 3]
            solids[name] = StlMesh(placed, mesh.faces)
        return solids[name]

    out = []
    for joint in kit.joints + kit.doc.get("fixed_joints", []):
        parent, child = joint["parent"], joint["child"]
        if files.get(parent) and files.get(child) and parent in poses and child in poses:
            a, b = solid(parent), solid(child)
            bound = point_gap(a, b)
            gap = bound if bound <= clear else solid_gap(a, b)
            out.append((joint["name"], parent, child, gap))
    return out


def _m(value: float) -> str:
    """A gap in metres to 0.1 mm (the published numbers' tolerance): 0.0392, not 0.03920000256."""
    return num(round(value, 4))


def check_connected(kit: Kit) -> list[Finding]:
    """One failed finding per joint whose links' solids are more than `CONNECTED_TOL` apart
    at home (one passing summary otherwise); an imported kit only reports."""
    imported = "source" in kit.doc
    # an imported kit only reports: the quick bound serves (its CAD meshes can be large)
    gaps = joint_gaps(kit, clear=float("inf") if imported else CONNECTED_TOL)
    apart = [g for g in gaps if g[3] > CONNECTED_TOL]
    tol = f"{CONNECTED_TOL:g}"
    if imported or not apart:
        worst = max(gaps, key=lambda g: g[3], default=None)
        detail = f"{len(gaps)} joints: each link's solid meets its parent's at home"
        if worst is not None:
            joint, parent, child, gap = worst
            detail += f" (largest gap at most {_m(gap)} m, {parent}-{child} at {joint})"
        if imported and apart:
            names = ", ".join(f"{c} from {p} ({_m(g)} m)" for _, p, c, g in apart[:5])
            more = f" and {len(apart) - 5} more" if len(apart) > 5 else ""
            detail = (
                f"imported robot, reported only: {len(apart)} of {len(gaps)} links may float "
                f"more than {tol} m from their parent at home (gaps at most): {names}{more}"
            )
        return [Finding("geometry.connected", True, detail)]
    return [
        Finding(
            "geometry.connected",
            False,
            f"at home, {child}'s solid does not meet {parent}'s across {joint}: "
            f"a gap of {_m(gap)} m (did the solids follow a moved joint?)",
            "0",
            _m(gap),
            tol,
            "m",
        )
        for joint, parent, child, gap in apart
    ]
