"""A written kit as a user sees it: robot.json plus file paths, and FK from robot.json alone."""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from simkit.errors import SimkitError
from simkit.model.kinematics import axis_angle, rpy_matrix, transform


@dataclass(frozen=True)
class Kit:
    """A kit folder on disk."""

    root: Path
    #: the URDF the kit was imported from (check/source compares them), when given
    source: Path | None = None

    @staticmethod
    def open(path: Path, source: Path | None = None) -> Kit:
        from simkit.kitio.kitread import read_folder_safely, robot_json_problem

        if not (path / "robot.json").is_file():
            raise SimkitError(f"{path}: not a kit folder (no robot.json)")
        read_folder_safely(
            path, read=False
        )  # one-line refusal: symlinks, special or oversized files
        why = robot_json_problem((path / "robot.json").read_bytes())
        if why:
            raise SimkitError(f"{path}: robot.json {why}")
        return Kit(path, source)

    def path(self, relative: str) -> Path:
        return self.root / relative

    @cached_property
    def doc(self) -> dict:
        return json.loads((self.root / "robot.json").read_text(encoding="utf-8"))

    @property
    def name(self) -> str:
        return self.doc["name"]

    @property
    def urdf(self) -> str:
        return self.doc["files"]["urdf"]

    @property
    def mjcf(self) -> str:
        return self.doc["files"]["mjcf"]

    @property
    def joints(self) -> list[dict]:
        return self.doc["joints"]

    @property
    def base_frame(self) -> str:
        return self.doc["base_frame"]

    def moved_links(self) -> set[str]:
        """Links a movable joint moves, directly or through the links above them (robot.json's
        joints and fixed joints). A floating base alone moves nothing relative to the rest: a
        rigid robot, floating or fixed (a drone and its props), has none."""
        above = {j["child"]: (j["parent"], True) for j in self.joints}
        above.update({j["child"]: (j["parent"], False) for j in self.doc.get("fixed_joints", [])})
        out: set[str] = set()
        for link in above:
            node, seen = link, set()
            while node in above and node not in seen:
                seen.add(node)
                parent, moves = above[node]
                if moves:
                    out.add(link)
                    break
                node = parent
        return out

    def fk(self, q, target: str | None = None) -> np.ndarray:
        """T_base_target from robot.json's joints (movable and fixed) and frames."""
        target = target or self.doc["tool_frame"]
        values = dict(zip([j["name"] for j in self.joints], q, strict=True))
        by_child = {j["child"]: j for j in self.joints + self.doc["fixed_joints"]}
        frame = self.doc["frames"].get(target)
        tail = np.eye(4)
        node = target
        if target not in by_child and frame is not None and "parent" in frame:
            tail = transform(frame["xyz"], rpy_matrix(frame["rpy"]))
            node = frame["parent"]
        chain = []
        while node != self.base_frame:
            joint = by_child[node]
            chain.append(joint)
            node = joint["parent"]
        out = np.eye(4)
        for joint in reversed(chain):
            out = out @ transform(joint["origin_xyz"], rpy_matrix(joint["origin_rpy"]))
            if joint["name"] in values:
                if joint["type"] == "prismatic":
                    out = out @ transform(np.asarray(joint["axis"]) * values[joint["name"]])
                else:
                    out = out @ transform(
                        (0, 0, 0), axis_angle(joint["axis"], values[joint["name"]])
                    )
        return out @ tail
