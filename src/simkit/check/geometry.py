"""Checks of the written collision pieces and GLB (issue 3), with numpy only so a warm build
stays fast: pieces per link, convexity, cover of the visual mesh, and GLB FK vs robot.json."""

from __future__ import annotations

import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.fk import fk_agrees
from simkit.check.kit import Kit
from simkit.check.mujoco import random_configs
from simkit.check.readers.glb import read_glb
from simkit.kitio.obj import read_mesh
from simkit.kitio.stl import from_stl
from simkit.model.hull import facet_depth, facet_planes, plane_max
from simkit.model.kinematics import axis_angle, quat_matrix, transform

MAX_PIECES = 10  # kit page: "convex pieces per link, up to ten"
CONVEX_TOL = 1e-6  # m: float32 STL round-off on a face plane
COVER_TOL = 1e-5  # m: a visual vertex may sit this far outside the pieces (float32 files)
GLB_FK_TOL = 1e-6  # m and rotation-matrix entries: 10 significant digits in the GLB JSON


def _outside(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """How far each point lies outside the convex mesh's face planes (<= 0: inside)."""
    tri = vertices[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(n, axis=1)
    keep = length > 1e-12
    n = n[keep] / length[keep, None]
    d = np.einsum("ij,ij->i", n, tri[keep, 0])
    return (points @ n.T - d).max(axis=1)


def _cover_gap(points: np.ndarray, pieces: list[np.ndarray]) -> float:
    """The largest distance (m) of a point outside every piece's convex hull; 0 when each
    lies in one: each point against the facet planes of each piece (qhull's) that can hold
    its maximum (model/hull.py `plane_max`).
    (qhull's tetrahedra held most points first, but their walk took up to 20 s on a few
    hundred points just outside a thin piece; a visual mesh's vertices lie on its hull.)"""
    from scipy.spatial import QhullError

    points = np.asarray(points, dtype=float)
    hulls = []
    for vertices in pieces:
        try:
            hulls.append(facet_planes(vertices))
        except (QhullError, ValueError):  # flat or too few points: holds nothing
            continue
    if not len(points):
        return 0.0
    if not hulls:
        return float("inf")
    depth = np.min([plane_max(points, hull.equations) for hull in hulls], axis=0)
    return max(0.0, float(depth.max()))


#: m: a dent shallower than this is measured no closer (model/hull.py `facet_depth`)
DENT_FLOOR = 1e-12


def _dent(vertices: np.ndarray, faces: np.ndarray) -> float:
    """How deep the mesh's surface lies inside its own convex hull (m): 0 for a convex mesh.
    A face lies on the hull's boundary exactly when its centre does, so the vertices and face
    centres are tested."""
    from scipy.spatial import QhullError

    samples = np.vstack([vertices, vertices[faces].mean(axis=1)])
    try:
        hull = facet_planes(vertices)
    except (QhullError, ValueError):  # flat or too few points: no solid to be inside of
        return 0.0
    return max(0.0, -float(facet_depth(samples, hull, -DENT_FLOOR).min()))


def _source_given(kit: Kit, report: dict) -> set[str]:
    """Links of an imported kit (robot.json has a `source` block) whose collision is the
    source's own (`given`): issue 42, class 6. The source's collision is what it is, so a
    visual it leaves out (a decorative ring 0.06 mm proud of the body, a collision that is a
    simplified copy of the visual) is reported, not failed. A spec robot has no `source`
    block and keeps the strict rule."""
    if not kit.doc.get("source"):
        return set()
    return {name for name, entry in report.items() if entry.get("method") == "given"}


def _given_note(gaps: dict[str, float]) -> str:
    """One line on the visual the source's collision leaves out (empty when it covers)."""
    out = {n: g for n, g in sorted(gaps.items()) if g > COVER_TOL}
    if not out:
        return ""
    worst = max(out.values())
    return (
        f"; the source's own collision leaves visual vertices up to {worst:.3g} m outside on "
        f"{len(out)} link(s), reported as given: {', '.join(out)}"
    )


def check_collision(kit: Kit) -> list[Finding]:
    """Every link: at most ten pieces, each convex, together covering the visual mesh's
    vertices (an imported kit's `given` links: reported, `_source_given`); robot.json's
    `geometry` piece counts match the files."""

    most, worst_convex, worst_cover, mismatched = 0, 0.0, 0.0, []
    report = {
        g["name"]: g.get("collision") or {} for g in kit.doc.get("geometry", {}).get("links", [])
    }
    given, given_gaps = _source_given(kit, report), {}
    for link in kit.doc["links"]:
        paths = link["mesh"]["collision"]
        if not paths:
            continue
        most = max(most, len(paths))
        if report.get(link["name"], {}).get("pieces") != len(paths):
            mismatched.append(link["name"])
        pieces = [read_mesh(p, kit.path(p).read_bytes()) for p in paths]
        for piece in pieces:
            worst_convex = max(worst_convex, _dent(piece.vertices, piece.faces))
        if link["mesh"]["visual"]:
            visual = from_stl(kit.path(link["mesh"]["visual"]).read_bytes()).vertices
            gap = _cover_gap(visual, [p.vertices for p in pieces])
            if link["name"] in given and gap > COVER_TOL:
                given_gaps[link["name"]] = gap
            else:
                worst_cover = max(worst_cover, gap)
    return [
        require(
            "collision.pieces",
            most <= MAX_PIECES,
            f"at most {MAX_PIECES} convex pieces per link (most: {most})",
        ),
        compare(
            "collision.convex",
            "deepest point of a piece's surface inside its own convex hull",
            0.0,
            worst_convex,
            CONVEX_TOL,
            "m",
        ),
        compare(
            "collision.cover",
            "largest distance of a visual vertex outside every piece" + _given_note(given_gaps),
            0.0,
            worst_cover,
            COVER_TOL,
            "m",
        ),
        require(
            "collision.report",
            not mismatched,
            "robot.json geometry pieces match the files"
            + (f" except {mismatched}" if mismatched else ""),
        ),
    ]


def _xyzw_matrix(q) -> np.ndarray:
    """glTF stores quaternions as (x, y, z, w)."""
    x, y, z, w = q
    return quat_matrix((w, x, y, z))


def glb_world(doc: dict, q: dict[str, float]) -> dict[str, np.ndarray]:
    """World pose of every named GLB node with joint values `q` (name -> rad or m) applied
    about the axis in each node's extras, as the kit page's "GLB" section says to."""
    out: dict[str, np.ndarray] = {}

    def walk(index: int, parent: np.ndarray) -> None:
        node = doc["nodes"][index]
        local = transform(
            node.get("translation", (0, 0, 0)), _xyzw_matrix(node.get("rotation", (0, 0, 0, 1)))
        )
        joint = node.get("extras", {}).get("joint", {})
        value = q.get(joint.get("name", ""), 0.0)
        if joint.get("type") in ("revolute", "continuous"):
            local = local @ transform((0, 0, 0), axis_angle(joint["axis"], value))
        elif joint.get("type") == "prismatic":
            local = local @ transform(np.asarray(joint["axis"]) * value)
        world = parent @ local
        out[node.get("name", str(index))] = world
        for child in node.get("children", []):
            walk(child, world)

    for root in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        walk(root, np.eye(4))
    return out


def check_glb(kit: Kit) -> list[Finding]:
    """The GLB parses, has a node per link, and its nodes rotated by seeded random joint
    values put the tool frame where robot.json's FK does."""

    rel = kit.doc.get("files", {}).get("glb", f"glb/{kit.name}.glb")
    path = kit.path(rel)
    if not path.is_file():
        return [require("glb.file", False, f"{rel} is missing")]
    try:
        doc, _binary = read_glb(path.read_bytes())
    except (ValueError, KeyError) as exc:
        return [require("glb.file", False, f"{rel}: {exc}")]
    names = {node.get("name") for node in doc["nodes"]}
    missing = [link["name"] for link in kit.doc["links"] if link["name"] not in names]
    findings = [
        require(
            "glb.nodes",
            not missing,
            "a GLB node per link" + (f"; missing {missing}" if missing else ""),
        )
    ]
    tool = kit.doc.get("tool_frame")
    if tool and tool in names and kit.joints:
        joint_names = [j["name"] for j in kit.joints]

        def tool_pose(q: np.ndarray) -> np.ndarray:
            world = glb_world(doc, dict(zip(joint_names, q, strict=True)))
            return np.linalg.inv(world[kit.base_frame]) @ world[tool]

        configs = random_configs(kit, 10, seed=2)
        findings += fk_agrees(kit, "glb.fk", "GLB nodes", tool_pose, configs, GLB_FK_TOL)
    return findings
