"""USD colliders as UsdPhysics' parser reads them vs the MJCF in MuJoCo: count per link, convex
hulls for meshes, primitive sizes and poses, and filtered pairs vs MJCF <exclude>."""

from __future__ import annotations

import mujoco
import numpy as np

from simkit.check.findings import Finding, compare, require
from simkit.check.readers.usd import matrix


def collision_findings(parsed: dict, mj, links: dict[str, str]) -> list[Finding]:
    """Colliders per link as UsdPhysics parses them vs MJCF collision geoms; mesh colliders are
    convex hulls; filtered pairs vs MJCF <exclude>."""
    from pxr import UsdPhysics

    count = dict.fromkeys(links.values(), 0)
    hulls = True
    for kind, (_paths, descs) in parsed.items():
        if not str(kind).endswith("Shape"):
            continue
        for d in descs:
            count[str(d.rigidBody)] = count.get(str(d.rigidBody), 0) + 1
            if kind == UsdPhysics.ObjectType.MeshShape:
                hulls &= str(d.approximation) == "convexHull"
    expected = [
        sum(
            1
            for g in range(mj.ngeom)
            if mj.geom_bodyid[g] == mj.body(n).id and (mj.geom_contype[g] or mj.geom_conaffinity[g])
        )
        for n in links
    ]
    name_of = {path: name for name, path in links.items()}
    filtered = set()
    for path, desc in zip(*parsed.get(UsdPhysics.ObjectType.RigidBody, ([], [])), strict=True):
        for other in desc.filteredCollisions:
            filtered.add(tuple(sorted((name_of.get(str(path)), name_of.get(str(other))))))
    excluded = set()
    for sig in mj.exclude_signature:
        a, b = int(sig) >> 16, int(sig) & 0xFFFF
        excluded.add(tuple(sorted((mj.body(a).name, mj.body(b).name))))
    return [
        compare(
            "usd.colliders",
            "colliders per link (UsdPhysics parser) vs MJCF collision geoms",
            expected,
            [count[p] for p in links.values()],
            0,
            "count",
        ),
        *_primitive_findings(parsed, mj),
        require("usd.convex_hull", hulls, "every mesh collider has approximation convexHull"),
        require(
            "usd.filtered_pairs",
            filtered == excluded,
            f"filtered pairs {sorted(filtered)} equal the MJCF excludes {sorted(excluded)}",
        ),
    ]


def _primitive_findings(parsed: dict, mj) -> list[Finding]:
    """Collision primitives (size, axis, pose in the link) vs the MJCF geom of the same name
    (`LINK_collision_NN` there, or `LINK_collision` for a link's only primitive;
    `LINK/collisions/collision_NN` here)."""
    exp, act, missing = [], [], []
    for kind, (paths, descs) in parsed.items():
        if str(kind).rsplit(".", 1)[-1] not in (
            "CubeShape",
            "SphereShape",
            "CapsuleShape",
            "CylinderShape",
        ):
            continue
        for path, d in zip(paths, descs, strict=True):
            name = f"{str(d.rigidBody).rsplit('/', 1)[-1]}_{str(path).rsplit('/', 1)[-1]}"
            geom = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, name)
            if geom < 0 and name.endswith("_collision_00"):  # a link's only primitive
                geom = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, name[:-3])
            if geom < 0:
                missing.append(name)
                continue
            if hasattr(d, "halfExtents"):
                size = list(d.halfExtents)
            elif hasattr(d, "halfHeight"):  # round shapes run along z in both formats
                size = [d.radius, d.halfHeight, 0.0 if str(d.axis).endswith("Z") else np.nan]
            else:
                size = [d.radius, 0.0, 0.0]
            pose = np.eye(4)
            rot = np.zeros(9)
            mujoco.mju_quat2Mat(rot, mj.geom_quat[geom])
            pose[:3, :3], pose[:3, 3] = rot.reshape(3, 3), mj.geom_pos[geom]
            theirs = matrix(d.localPos, d.localRot)
            if hasattr(d, "halfHeight"):  # round about its axis: MJCF fromto picks its own x, y
                pose[:3, :2] = theirs[:3, :2] = 0.0  # and its axis either way round
                pose[:3, 2] *= 1.0 if pose[:3, 2] @ theirs[:3, 2] >= 0 else -1.0
            exp.append(np.concatenate([mj.geom_size[geom], pose[:3].ravel()]))
            act.append(np.concatenate([size, theirs[:3].ravel()]))
    out = (
        [
            require(
                "usd.primitives.names",
                not missing,
                f"MJCF geoms for USD primitives (missing {missing})",
            )
        ]
        if missing
        else []
    )
    if exp:
        out.append(
            compare(
                "usd.primitives",
                "collision primitive size and pose vs MJCF geom",
                exp,
                act,
                1e-6,
                "m or 1",
            )
        )
    return out
