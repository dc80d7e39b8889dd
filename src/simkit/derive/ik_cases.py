"""The kit's IK reference cases (ik_cases.json) for a wrist-partitioned 6R arm.

Source: 000_5f76ade803e16979.txt, "IK reference cases": twelve cases, each with a seed pose,
the straight Cartesian move resolved from it, the target pose of tool0 in base_link, the
solution reached by following the move (`expected`, with its branch flags) and every other
solution inside the joint limits (`all_solutions`). Seeded by the spec's `seed`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from simkit import __version__
from simkit.model.ik import (
    BRANCH_FLAGS,
    METHOD,
    ArmChain,
    nearest,
    pose_error,
    principal_solutions,
    solve,
)
from simkit.model.kinematics import axis_angle
from simkit.model.robot import Robot

Depth = Callable[[Sequence[float]], float]

N_CASES = 12
MOVE_STEPS = 40  # straight-line steps from the seed pose to the target
MOVE_LENGTH = 0.15  # m, seed tool0 position to target
MOVE_ANGLE = 0.3  # rad, seed tool0 orientation to target
MAX_STEP = 0.1  # rad, largest joint change between two steps of a resolved move
MARGIN = 0.25  # |cos J5| and |sin(J3 - J3_stretched)| stay above this: away from singularities
MIN_RADIUS = 0.2  # m, wrist centre from the J1 axis
MIN_HEIGHT = 0.05  # m, wrist centre and tool0 above base_link
TOLERANCE = {"position_m": 1e-6, "rotation": 1e-6, "joint_rad": 1e-6}


def _conditioned(arm: ArmChain, q) -> bool:
    """True when q is well away from the wrist, elbow and shoulder singularities, inside the
    limits, and keeps the wrist and tool above base_link."""
    if not arm.within_limits(q, tol=0.0):
        return False
    th = np.asarray(q) * arm.signs
    t, c = arm.origins, arm.origins[3] + arm.origins[4]
    stretched = np.arctan2(t[2, 0] * c[2] - t[2, 2] * c[0], t[2, 0] * c[0] + t[2, 2] * c[2])
    frames = arm.frames(q)
    wrist = frames[4][:3, 3] - frames[0][:3, 3]
    tool = arm.fk(q)
    return bool(
        abs(np.cos(th[4])) > MARGIN
        and abs(np.sin(th[2] - stretched)) > MARGIN
        and np.hypot(wrist[0], wrist[1]) > MIN_RADIUS
        and frames[4][2, 3] > MIN_HEIGHT
        and tool[2, 3] > MIN_HEIGHT
    )


def _unwrapped(q, ref) -> np.ndarray:
    """q with each angle moved by 2 pi multiples to lie nearest ref."""
    q, ref = np.asarray(q), np.asarray(ref)
    return ref + (q - ref + np.pi) % (2 * np.pi) - np.pi


def resolve_move(arm: ArmChain, q_seed, T_target: np.ndarray) -> np.ndarray | None:
    """Joint poses along the straight line from FK(q_seed) to T_target (position linear,
    orientation turning about one fixed axis), each the IK solution nearest the previous;
    None if the move leaves the limits, nears a singularity or jumps."""
    T0 = arm.fk(q_seed)
    rel = T_target[:3, :3] @ T0[:3, :3].T
    angle = float(np.arccos(np.clip((np.trace(rel) - 1) / 2, -1.0, 1.0)))
    axis = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    axis = axis / np.linalg.norm(axis) if angle > 1e-12 else np.array([0.0, 0.0, 1.0])
    path, prev = [np.asarray(q_seed, dtype=float)], np.asarray(q_seed, dtype=float)
    for k in range(1, MOVE_STEPS + 1):
        s = k / MOVE_STEPS
        T = np.eye(4)
        T[:3, :3] = axis_angle(axis, s * angle) @ T0[:3, :3]
        T[:3, 3] = (1 - s) * T0[:3, 3] + s * T_target[:3, 3]
        options = [_unwrapped(sol.q, prev) for sol in principal_solutions(arm, T, float(prev[3]))]
        if not options:
            return None
        best = min(options, key=lambda q: float(np.abs(q - prev).max()))
        if (
            np.abs(best - prev).max() > MAX_STEP
            or not _conditioned(arm, best)
            or pose_error(arm.fk(best), T) > 1e-9
        ):
            return None
        path.append(best)
        prev = best
    return np.array(path)


def _free(depth: Depth | None, q) -> bool:
    """No self-contact at q (issue 12: seeds and expected solutions are collision-free)."""
    return depth is None or depth(list(q)) <= 0.0


def _listed(solution, depth: Depth | None) -> dict:
    """A listed solution as JSON, flagged `self_collision` with its depth (m) if links meet."""
    out = solution.as_json()
    found = 0.0 if depth is None else depth(list(solution.q))
    if found > 0.0:
        out.update(self_collision=True, self_collision_depth_m=found)
    return out


def _case(
    arm: ArmChain,
    rng: np.random.Generator,
    sector: tuple[float, float],
    depth: Depth | None = None,
) -> dict | None:
    """One candidate case with J1 inside `sector`, or None if it fails a condition."""
    lo, hi = np.maximum(arm.lower, -np.pi), np.minimum(arm.upper, np.pi)
    q_seed = rng.uniform(lo, hi)
    q_seed[0] = rng.uniform(*sector)
    direction = rng.normal(size=3)
    turn = rng.normal(size=3)
    if not _conditioned(arm, q_seed) or not _free(depth, q_seed):
        return None
    T0 = arm.fk(q_seed)
    target = np.eye(4)
    target[:3, 3] = T0[:3, 3] + MOVE_LENGTH * direction / np.linalg.norm(direction)
    target[:3, :3] = axis_angle(turn / np.linalg.norm(turn), MOVE_ANGLE) @ T0[:3, :3]
    path = resolve_move(arm, q_seed, target)
    if path is None:
        return None
    solutions = solve(arm, target)
    expected = nearest(solutions, path[-1])
    if expected is None or np.abs(np.subtract(expected.q, path[-1])).max() > 1e-9:
        return None
    if not _free(depth, expected.q):
        return None
    others = [s for s in solutions if s is not expected]
    return {
        "seed": {
            "q": list(q_seed),
            "tool0": {"xyz": list(T0[:3, 3]), "rotation": T0[:3, :3].tolist()},
        },
        "move": {
            "type": "straight line in base_link: position linear, orientation turning about "
            "one fixed axis at a constant rate",
            "steps": MOVE_STEPS,
            "length_m": MOVE_LENGTH,
            "rotation_rad": MOVE_ANGLE,
            "max_joint_step_rad": float(np.abs(np.diff(path, axis=0)).max()),
            "q": [list(row) for row in path],
        },
        "target": {"xyz": list(target[:3, 3]), "rotation": target[:3, :3].tolist()},
        "expected": expected.as_json(),
        "all_solutions": [_listed(s, depth) for s in others],
    }


def reference_cases(arm: ArmChain, seed: int, depth: Depth | None = None) -> list[dict]:
    """N_CASES cases spread over the workspace: J1 of case i in the i-th of N_CASES equal
    sectors of its range (within +-pi), the rest seeded-random within the limits; with
    `depth` (self_contact.depth_function), seeds and expected solutions free of self-contact."""
    rng = np.random.default_rng(seed)
    lo, hi = max(arm.lower[0], -np.pi), min(arm.upper[0], np.pi)
    edges = np.linspace(lo, hi, N_CASES + 1)
    cases = []
    for i in range(N_CASES):
        for _attempt in range(2000):
            case = _case(arm, rng, (edges[i], edges[i + 1]), depth)
            if case is not None:
                cases.append({"name": f"case_{i + 1:02d}", **case})
                break
        else:
            raise ValueError(f"no IK reference case found with J1 in sector {i + 1}")
    return cases


def cases_document(robot: Robot, arm: ArmChain, depth: Depth | None = None) -> dict:
    """ik_cases.json: standalone (chain, units, frames, tolerance, solver, cases)."""

    return {
        "robot": robot.name,
        "title": robot.title,
        "units": {"length": "m", "angle": "rad"},
        "frames": {
            "base": arm.base,
            "tip": arm.tool,
            "target": f"pose of {arm.tool} in {arm.base}: xyz (m) and rotation matrix (rows)",
        },
        "chain": {
            "base": arm.base,
            "tip": arm.tool,
            "joints": [
                {
                    "name": n,
                    "parent": p,
                    "child": c,
                    "origin_xyz": list(o),
                    "axis": list(a),
                    "lower": lo,
                    "upper": hi,
                }
                for n, p, c, o, a, lo, hi in zip(
                    arm.names,
                    arm.parents,
                    arm.children,
                    arm.origins,
                    arm.axes,
                    arm.lower,
                    arm.upper,
                    strict=True,
                )
            ],
            "tool": {
                "name": arm.tool,
                "parent": arm.children[5],
                "xyz": list(arm.tool_xyz),
                "rpy": list(arm.tool_rpy),
                "T_parent_tool": arm.T_6_tool.tolist(),
            },
            "fk": "T = product over joints of Trans(origin_xyz) Rot(axis, q), then "
            "T_parent_tool; every joint origin is a pure translation",
        },
        "tolerance": TOLERANCE,
        "solver": {
            "name": "simkit.model.ik",
            "method": METHOD,
            "branch_flags": BRANCH_FLAGS,
            "expected": "the solution reached by following the straight move from the seed "
            f"pose in {MOVE_STEPS} steps, each step the solution nearest the previous one",
            "provenance": f"solved by simkit {__version__} (src/simkit/model/ik.py) on this "
            "kit's own chain, the joints of robot.json; not RosieOS's resolver",
            "seed": robot.seed,
        },
        "self_collision": "seeds and expected solutions are free of self-contact (MuJoCo, "
        "the kit's collision geometry, adjacent links excluded); a listed solution where links "
        "meet has self_collision: true and self_collision_depth_m (m)",
        "cases": reference_cases(arm, robot.seed, depth),
    }
