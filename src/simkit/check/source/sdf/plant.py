"""Reading an SDFormat file (or the kit's URDF) with Drake's parser (libsdformat inside
`pydrake`), not simkit's reader: `Plant` is a finalized MultibodyPlant with its bodies,
joints and named frames by their names scoped below the file's top model (`a::b` in nested
model `a`), each body's kit link frame (its inboard joint's frame on the child) and poses in
the world (m). Kept apart from the comparison (comparison.py) because it is the one place that
builds plants; pydrake is imported lazily, inside the functions that need it.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np


class Plant:
    """A file read by Drake into a finalized MultibodyPlant; bodies and joints by their
    names scoped below the file's top model (`a::b` in nested model `a`)."""

    def __init__(self, path: Path, models: Path) -> None:
        from pydrake.multibody.parsing import Parser
        from pydrake.multibody.plant import MultibodyPlant

        self.plant = MultibodyPlant(0.0)
        parser = Parser(self.plant)
        for folder in sorted(p for p in models.iterdir() if p.is_dir()):
            if not parser.package_map().Contains(folder.name):
                parser.package_map().Add(folder.name, str(folder))
        logger = logging.getLogger("drake")  # its parse warnings (unsupported friction)
        level = logger.level
        logger.setLevel(logging.ERROR)
        try:
            top = parser.AddModels(str(path))
        finally:
            logger.setLevel(level)
        self.plant.Finalize()
        self.context = self.plant.CreateDefaultContext()
        joints = [self.plant.get_joint(_index("Joint", i)) for i in range(self.plant.num_joints())]
        names = [self.plant.GetModelInstanceName(m) for m in top]
        moving = [n for n in names if any(_moves(j) and self._top(j, [n]) for j in joints)]
        names = moving or names  # a world: its robot, as the import takes it, not scenery
        self.bodies, self.joints = {}, {}
        for i in range(self.plant.num_bodies()):
            body = self.plant.get_body(_index("Body", i))
            if body.index() != self.plant.world_body().index() and self._top(body, names):
                self.bodies[self._scoped(body, names)] = body
        for joint in joints:
            if self._top(joint, names):
                self.joints[self._scoped(joint, names)] = joint
        #: the named frames that are no body's (an SDF `<frame>`; Drake's joint frames too)
        self.frames = {}
        for i in range(self.plant.num_frames()):
            frame = self.plant.get_frame(_index("Frame", i))
            if not frame.is_body_frame() and self._top(frame, names):
                self.frames.setdefault(self._scoped(frame, names), frame)

    def _top(self, element, tops: list[str]) -> bool:
        """Whether `element` lies in one of the models `tops` (or a model nested in one)."""
        instance = self.plant.GetModelInstanceName(element.model_instance())
        return any(instance == t or instance.startswith(t + "::") for t in tops)

    def _scoped(self, element, tops: list[str]) -> str:
        instance = self.plant.GetModelInstanceName(element.model_instance())
        for top in tops:
            if instance.startswith(top + "::"):
                return f"{instance[len(top) + 2 :]}::{element.name()}"
        return element.name()

    def inboard(self, body):
        """The joint whose child is `body` (None for a free root)."""
        for joint in self.joints.values():
            if (
                joint.child_body().index() == body.index()
                and joint.type_name() != "quaternion_floating"
            ):
                return joint
        return None

    def kit_frame(self, body) -> np.ndarray:
        """X_BK: the kit's link frame in the body frame (the inboard joint's frame)."""
        joint = self.inboard(body)
        if joint is None:
            return np.eye(4)
        return joint.frame_on_child().GetFixedPoseInBodyFrame().GetAsMatrix4()

    def pose(self, body) -> np.ndarray:
        return self.plant.EvalBodyPoseInWorld(self.context, body).GetAsMatrix4()

    def frame_pose(self, frame) -> np.ndarray:
        return frame.CalcPoseInWorld(self.context).GetAsMatrix4()


def _moves(joint) -> bool:
    return joint.type_name() not in ("weld", "quaternion_floating")


def _index(kind: str, i: int):
    from pydrake.multibody import tree

    return getattr(tree, f"{kind}Index")(i)
