"""The source-model pieces an SDF model's joints and frames share (tree.py, universal.py): a
frame's pose in the model frame, an origin `Pose`, an axis in its joint frame
(`expressed_in`), a joint's `Limit` and `Dynamics`, all numbers plain floats as the reader
computed them (one that is not finite is refused by formats.load: formats/finite.py)."""

from __future__ import annotations

import numpy as np

from simkit.importer.formats.sdf.frames import MODEL, WORLD, inverse, numbers, rpy_of, scoped
from simkit.importer.read.model import At, Dynamics, Limit, Pose

#: |limit| at or above which an SDF limit means none (the specification's default is 1e16)
NO_LIMIT = 1e15


def vec(values) -> tuple[float, ...]:
    """Numbers as a tuple of plain floats (the model is typed: no numpy scalars)."""
    return tuple(float(v) for v in np.ravel(values))


def in_model(model, name: str, element) -> np.ndarray:
    """A frame's pose in the top model frame (the world: the model's pose inverted)."""
    if name == WORLD:
        return inverse(model.source.placed)
    return model.frames.in_model(name, element)


def origin(x: np.ndarray, line: int | None) -> Pose:
    """The `Pose` of a 4x4 transform (m; URDF roll-pitch-yaw, rad), placed on `line`."""
    return Pose(vec(x[:3, 3]), vec(rpy_of(x[:3, :3])), At("origin", None, line))  # type: ignore[arg-type]


def axis_in_joint(model, joint, tag: str, x_joint: np.ndarray) -> np.ndarray:
    """The unit axis of `<axis>` (or `<axis2>`) in the joint frame: its `<xyz>` expressed in
    the joint frame unless `expressed_in` (or 1.4-1.6 `use_parent_model_frame`) says."""
    src = model.source
    axis = joint.find(tag)
    xyz = axis.find("xyz") if axis is not None else None
    if xyz is None:
        raise src.fail(joint, f"a {joint.get('type')} joint without <{tag}><xyz>")
    vector = np.asarray(numbers(src, xyz, xyz.text, 3))
    if not np.linalg.norm(vector):
        raise src.fail(xyz, "a zero axis")
    frame = xyz.get("expressed_in")
    if not frame and (axis.findtext("use_parent_model_frame") or "").strip() in ("true", "1"):
        frame = MODEL
    if frame:
        rot = x_joint[:3, :3].T @ in_model(model, scoped(xyz.get("scope", ""), frame), xyz)[:3, :3]
        vector = rot @ vector
    return vector / np.linalg.norm(vector)


def limits(src, axis, kind: str, line: int | None) -> tuple[str, Limit | None, Dynamics | None]:
    """The joint's type (a revolute joint without finite limits is continuous), its limits
    (None: none given; a continuous joint keeps no position limits) and its dynamics."""
    limit = axis.find("limit")

    def value(tag: str) -> float | None:
        found = None if limit is None else limit.find(tag)
        return None if found is None else numbers(src, found, found.text, 1)[0]

    lower, upper, effort, velocity = (value(t) for t in ("lower", "upper", "effort", "velocity"))
    bounded = lower is not None and upper is not None and max(abs(lower), abs(upper)) < NO_LIMIT
    if kind == "revolute" and not bounded:
        kind = "continuous"
    given = {"lower": lower, "upper": upper} if bounded else {}
    if effort is not None and effort > 0:
        given["effort"] = effort
    if velocity is not None and velocity > 0:
        given["velocity"] = velocity
    if kind == "continuous":
        given.update((k, None) for k in ("lower", "upper") if k in given)
    out = Limit(At("limit", None, line), **given) if given else None
    damping = axis.findtext("dynamics/damping")
    friction = axis.findtext("dynamics/friction")
    if not (damping or friction):
        return kind, out, None
    return (
        kind,
        out,
        Dynamics(At("dynamics", None, line), float(damping or 0), float(friction or 0)),
    )
