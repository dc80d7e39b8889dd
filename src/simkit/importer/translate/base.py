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

Arms are no legs (issue 32, class 7): a limb with a link that carries two or more movable
branches (a gripper's or hand's fingers) is an arm, and a robot whose root is `world` (the
URDF convention for the world frame, which Gazebo, Drake and PyBullet weld) joined to the
robot by a fixed joint is bolted there by its author: a rig with two arms hanging from its
torso stands on neither. (Legs whose meshes are missing, or a URDF with no geometry at all,
stand on the boxes the import estimates: translate/solids.py.)
"""

from __future__ import annotations

import numpy as np

from simkit.importer.read.model import Pose
from simkit.importer.read.source import Source
from simkit.importer.translate.convert import tree
from simkit.model.kinematics import rpy_matrix

#: share of the robot's height span (z at the zero pose) a leg reaches below the root
LEG = 0.25
#: m: and at least this far below it (a flat robot's arms are no legs)
MIN_DROP = 0.02
MOVABLE = ("revolute", "continuous", "prismatic", "planar", "floating", "spherical")
RANGED = ("revolute", "prismatic", "spherical")  # a limb with only continuous joints: wheels


def _transform(pose: Pose) -> np.ndarray:
    """The 4x4 matrix of a source model pose (m, rad)."""
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(pose.rpy)
    out[:3, 3] = pose.xyz
    return out


def _points(links: dict, by_child: dict, root: str) -> dict[str, np.ndarray]:
    """Each link's origin and CoM (rows, m) in the root frame at the zero pose."""
    poses = {root: np.eye(4)}
    pending = [n for n in links if n != root]
    while pending:
        rest = []
        for name in pending:
            parent = by_child[name].parent
            if parent in poses:
                poses[name] = poses[parent] @ _transform(by_child[name].origin)
            else:
                rest.append(name)
        if len(rest) == len(pending):
            break
        pending = rest
    out = {}
    for name, pose in poses.items():
        rows = [pose[:3, 3]]
        inertial = links[name].inertial
        if inertial is not None and inertial.mass_at is not None:
            rows.append((pose @ _transform(inertial.origin))[:3, 3])
        out[name] = np.array(rows)
    return out


def _limbs(links: dict, by_child: dict, root: str) -> list[tuple[list[str], bool]]:
    """The links of each branch that leaves the root's welded frame through a movable joint
    and has a joint with a range (revolute, prismatic, spherical: not only wheels), each with
    whether it is a hand (a link with two or more movable branches below it: fingers)."""
    kids: dict[str, list[str]] = {}
    for child, joint in by_child.items():
        kids.setdefault(joint.parent, []).append(child)

    def below(name: str) -> list[str]:
        out, stack = [], [name]
        while stack:
            node = stack.pop()
            out.append(node)
            stack.extend(kids.get(node, []))
        return out

    def hand(limb: list[str]) -> bool:
        return any(sum(by_child[kid].type in MOVABLE for kid in kids.get(n, [])) >= 2 for n in limb)

    limbs, stack = [], [root]
    while stack:  # the welded frame: the root and what fixed joints hold to it
        node = stack.pop()
        for child in kids.get(node, []):
            if by_child[child].type in MOVABLE:
                limb = below(child)
                if any(by_child[n].type in RANGED for n in limb):
                    limbs.append((limb, hand(limb)))
            else:
                stack.append(child)
    return limbs


#: the URDF convention for the world frame (Gazebo, Drake and PyBullet weld a `world` parent)
WORLD = "world"


def legs(source: Source) -> tuple[list[list[str]], str]:
    """The limbs that are legs (their links), deepest first, and the figures of the report
    line: how many limbs reach how far below the root, against which drop."""
    links, by_child, root = tree(source)
    points = _points(links, by_child, root)
    every = np.vstack(list(points.values()))
    span = float(every[:, 2].max() - every[:, 2].min())
    drop = max(LEG * span, MIN_DROP)
    limbs = [
        (-float(np.vstack([points[n] for n in limb if n in points])[:, 2].min()), limb, hand)
        for limb, hand in _limbs(links, by_child, root)
    ]
    deep = sorted(
        ((d, limb) for d, limb, hand in limbs if d >= drop and not hand), key=lambda x: -x[0]
    )
    found = [limb for _d, limb in deep]
    if len(found) >= 2:
        return found, (
            f"{len(found)} limbs reach {deep[-1][0]:.3g} m or more below the root link "
            f"'{root}' at the zero pose (legs; at least {drop:.3g} m, {LEG:g} of the "
            f"robot's {span:.3g} m height)"
        )
    hands = sum(hand for d, _limb, hand in limbs if d >= drop)
    return found, (
        f"{len(found) + hands} of {len(limbs)} limbs reach {drop:.3g} m below it at the zero "
        "pose; two would be legs"
        + (
            f", but {hands} of them branch into fingers (hands, no legs)"
            if hands and len(found) + hands >= 2
            else ""
        )
    )


def _bolted(source: Source) -> bool:
    """True when the root is `world` and a fixed joint holds the robot to it."""
    _links, by_child, root = tree(source)
    return root == WORLD and any(j.parent == root and j.type == "fixed" for j in by_child.values())


def decide(source: Source) -> tuple[bool, str]:
    """(floating, the report line's reason) from the URDF's structure."""
    found, figures = legs(source)
    root = tree(source)[2]
    if len(found) >= 2 and _bolted(source):
        return False, (
            f"fixed base: the {source.noun} bolts the robot to '{root}' with a fixed joint "
            f"({figures}); "
            "--floating-base lets it move"
        )
    if len(found) >= 2:
        return True, f"floating base: {figures}; --fixed-base bolts it at the root instead"
    return False, (
        f"fixed base: the root link '{root}' is bolted to the world ({figures}); "
        "--floating-base lets it move"
    )
