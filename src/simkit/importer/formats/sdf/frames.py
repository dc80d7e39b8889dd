"""SDFormat's frame semantics (sdformat.org/tutorials?tut=pose_frame_semantics), over one
model with its nested models flattened into scoped names (`a::b`).

Frames of a model scope: `__model__` (the model frame, also named by the model's own name in
its parent scope), each link, each joint, each `<frame>` and each nested model. Defaults, as
the specification gives them:

- a link's, frame's or nested model's `<pose>` is relative to the model frame;
- a joint's `<pose>` is relative to its CHILD link (not the parent, unlike URDF);
- a `<frame>` is attached to the model frame unless `attached_to` says otherwise, and its
  pose is relative to what it is attached to;
- `relative_to` names any frame of the same scope (or of a nested one, `a::b`).

Poses are 4x4 homogeneous transforms (m), angles rad; `<pose degrees="true">` and
`rotation_format="quat_xyzw"` (SDFormat 1.9) are read too. Cycles and unknown names are one
line each, naming the element.
"""

from __future__ import annotations

import numpy as np

MODEL = "__model__"
WORLD = "world"


def rpy_matrix(r: float, p: float, y: float) -> np.ndarray:
    """Rotation of SDFormat (and URDF) roll-pitch-yaw: Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])  # fmt: skip


def quat_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    """Rotation of a quaternion (normalised first)."""
    n = np.sqrt(x * x + y * y + z * z + w * w) or 1.0
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def rpy_of(mat: np.ndarray) -> np.ndarray:
    """URDF roll-pitch-yaw (rad) of a rotation matrix."""
    pitch = float(np.arcsin(np.clip(-mat[2, 0], -1.0, 1.0)))
    if abs(mat[2, 0]) < 1.0 - 1e-12:
        return np.array([np.arctan2(mat[2, 1], mat[2, 2]), pitch, np.arctan2(mat[1, 0], mat[0, 0])])
    return np.array([np.arctan2(-mat[1, 2], mat[1, 1]), pitch, 0.0])


def transform(rot: np.ndarray, xyz) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rot, np.asarray(xyz, dtype=float)
    return out


def inverse(x: np.ndarray) -> np.ndarray:
    rot = x[:3, :3].T
    return transform(rot, -rot @ x[:3, 3])


def numbers(source, element, text: str | None, count: int | None = None) -> list[float]:
    """The whitespace-separated numbers of an element's text; one line when malformed."""
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        raise source.fail(element, f"'{(text or '').strip()}' is not a list of numbers") from None
    if count is not None and len(values) != count:
        raise source.fail(element, f"{len(values)} numbers, {count} expected")
    if not all(np.isfinite(values)):
        raise source.fail(element, "a number is not finite")
    return values


def pose_of(source, pose) -> np.ndarray:
    """The transform a `<pose>` element writes (identity for None)."""
    if pose is None or not (pose.text or "").strip():
        return np.eye(4)
    quat = (pose.get("rotation_format") or "euler_rpy") == "quat_xyzw"
    values = numbers(source, pose, pose.text, 7 if quat else 6)
    if quat:
        return transform(quat_matrix(*values[3:]), values[:3])
    angles = np.radians(values[3:]) if pose.get("degrees") in ("true", "1") else values[3:]
    return transform(rpy_matrix(*angles), values[:3])


class Frames:
    """The frame graph of one model (flattened): name -> (element, relative-to name, pose
    in it), resolved to poses in the model frame on demand; `attached` maps a `<frame>` or
    nested model to the link it is attached to."""

    def __init__(self, source) -> None:
        self.source = source
        self.edges: dict[str, tuple[object, str, np.ndarray]] = {}
        self.attached: dict[str, str] = {}
        self._done: dict[str, np.ndarray] = {MODEL: np.eye(4)}

    def add(self, name: str, element, relative_to: str, pose: np.ndarray) -> None:
        if name in self.edges or name == MODEL:
            raise self.source.fail(element, f"frame name '{name}' is used twice in its model")
        self.edges[name] = (element, relative_to, pose)

    def in_model(self, name: str, element=None) -> np.ndarray:
        """The pose of frame `name` in the (top) model frame; one line for an unknown name
        or a cycle."""
        chain: list[str] = []
        here = name
        while here not in self._done:
            if here not in self.edges:
                raise self.source.fail(element, f"frame '{here}' is not defined")
            if here in chain:
                raise self.source.fail(element, f"frames form a cycle: {' -> '.join(chain)}")
            chain.append(here)
            element = self.edges[here][0]
            here = self.edges[here][1]
        for name_ in reversed(chain):
            _, up, pose = self.edges[name_]
            self._done[name_] = self._done[up] @ pose
        return self._done[name]

    def link_of(self, name: str, links: set[str], element=None) -> str:
        """The link a frame is attached to (a link is its own; the model frame and the world
        have none: returns the name itself)."""
        seen: list[str] = []
        while name not in links and name in self.attached:
            if name in seen:
                raise self.source.fail(element, f"frames attach in a cycle: {' -> '.join(seen)}")
            seen.append(name)
            name = self.attached[name]
        if name not in links and name not in (MODEL, WORLD):
            raise self.source.fail(element, f"'{name}' is attached to no link")
        return name


def scoped(scope: str, name: str) -> str:
    """A name written inside nested model `scope` as the top model's scoped name."""
    if name == WORLD:
        return WORLD
    if name == MODEL:
        return scope or MODEL
    if name.endswith("::" + MODEL):
        name = name[: -len("::" + MODEL)]
    return f"{scope}::{name}" if scope else name
