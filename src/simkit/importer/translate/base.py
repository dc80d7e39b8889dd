"""Fixed or floating base, decided from the robot's structure (a URDF does not say).

A robot stands on its limbs when two or more of them reach below its root: the legs of a
quadruped or a humanoid hang from the trunk or the pelvis, while an arm's base sits at the
bottom of the robot and its links rise from it. At the URDF's zero pose, each limb (a branch
leaving the root's welded frame through a movable joint) reaches as low as the lowest origin
or centre of mass of its links, in the root's frame. A limb is a leg when that is at least
`LEG` of the robot's height span (and `MIN_DROP`) below the root and it has a joint with a
range (a wheel, on continuous joints only, is no leg: a two-wheeler does not stand); two legs
make the base floating. Anything else keeps a fixed base (an arm bolted down, a wheeled
base on a stand, a drone on a test rig). `--fixed-base` and `--floating-base` override the
decision; the import reports it on one line either way.
"""

from __future__ import annotations

import numpy as np

from simkit.importer.read.source import Source
from simkit.importer.translate.convert import tree
from simkit.importer.translate.geometry import origin
from simkit.model.kinematics import rpy_matrix

#: share of the robot's height span (z at the zero pose) a leg reaches below the root
LEG = 0.25
#: m: and at least this far below it (a flat robot's arms are no legs)
MIN_DROP = 0.02
MOVABLE = ("revolute", "continuous", "prismatic", "planar", "floating", "spherical")
RANGED = ("revolute", "prismatic", "spherical")  # a limb with only continuous joints: wheels


def _transform(source: Source, element) -> np.ndarray:
    """The 4x4 pose of an element's `<origin>` (m, rad)."""
    xyz, rpy = origin(source, element)
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(rpy)
    out[:3, 3] = xyz
    return out


def _points(source: Source, links: dict, by_child: dict, root: str) -> dict[str, np.ndarray]:
    """Each link's origin and CoM (rows, m) in the root frame at the zero pose."""
    poses = {root: np.eye(4)}
    pending = [n for n in links if n != root]
    while pending:
        rest = []
        for name in pending:
            parent = by_child[name].find("parent").get("link")
            if parent in poses:
                poses[name] = poses[parent] @ _transform(source, by_child[name])
            else:
                rest.append(name)
        if len(rest) == len(pending):
            break
        pending = rest
    out = {}
    for name, pose in poses.items():
        rows = [pose[:3, 3]]
        inertial = links[name].find("inertial")
        if inertial is not None and inertial.find("mass") is not None:
            rows.append((pose @ _transform(source, inertial))[:3, 3])
        out[name] = np.array(rows)
    return out


def _limbs(links: dict, by_child: dict, root: str) -> list[list[str]]:
    """The links of each branch that leaves the root's welded frame through a movable joint
    and has a joint with a range (revolute, prismatic, spherical: not only wheels)."""
    kids: dict[str, list[str]] = {}
    for child, joint in by_child.items():
        kids.setdefault(joint.find("parent").get("link"), []).append(child)

    def below(name: str) -> list[str]:
        out, stack = [], [name]
        while stack:
            node = stack.pop()
            out.append(node)
            stack.extend(kids.get(node, []))
        return out

    limbs, stack = [], [root]
    while stack:  # the welded frame: the root and what fixed joints hold to it
        node = stack.pop()
        for child in kids.get(node, []):
            if by_child[child].get("type") in MOVABLE:
                limb = below(child)
                if any(by_child[n].get("type") in RANGED for n in limb):
                    limbs.append(limb)
            else:
                stack.append(child)
    return limbs


def decide(source: Source) -> tuple[bool, str]:
    """(floating, the report line's reason) from the URDF's structure."""
    links, by_child, root = tree(source)
    points = _points(source, links, by_child, root)
    every = np.vstack(list(points.values()))
    span = float(every[:, 2].max() - every[:, 2].min())
    drop = max(LEG * span, MIN_DROP)
    depths = sorted(
        (-float(np.vstack([points[n] for n in limb if n in points])[:, 2].min()) for limb in
         _limbs(links, by_child, root)),
        reverse=True,
    )  # fmt: skip
    legs = [d for d in depths if d >= drop]
    if len(legs) >= 2:
        return True, (
            f"floating base: {len(legs)} limbs reach {min(legs):.3g} m or more below the root "
            f"link '{root}' at the zero pose (legs; at least {drop:.3g} m, {LEG:g} of the "
            f"robot's {span:.3g} m height); --fixed-base bolts it at the root instead"
        )
    return False, (
        f"fixed base: the root link '{root}' is bolted to the world ({len(legs)} of "
        f"{len(depths)} limbs reach {drop:.3g} m below it at the zero pose; two would be "
        "legs); --floating-base lets it move"
    )
