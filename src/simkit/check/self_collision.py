"""Self-collision of a written kit: no two bodies of the kit's MJCF penetrate by more than 1 mm
at the named poses, the IK reference cases, every benchmark sample (both cycles) and single-joint
sweeps from each joint's lower to its upper limit in 2 deg steps, the others at home.

Why (issue 12): the Rosie arms used to pass links through each other inside their own limits,
and no check saw it. MuJoCo on the kit's own MJCF (its collision geoms, contact excludes and
parent-child filter) gives the contacts a user's simulation gets. A failure names the
configuration, the two links and the depth in mm.

Joints whose limits a source publishes (not `estimated` in robot.json) keep them even where
links meet inside (Asimov's hip roll lets the legs touch); their sweep covers the collision-free
range robot.json records (`geometry.self_collision.free_ranges`), and the check verifies that
record: free inside, and in contact one step beyond it.

Mimic joints move with their leaders in every configuration (robot.json's `mimic`, the MJCF's
equality): a follower is not swept alone, its leader's sweep moves it (issue 32).
"""

from __future__ import annotations

import csv
import itertools
import json
import math

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.simulate import self_collision as sc

TOLERANCE = sc.TOLERANCE  # m: deepest allowed penetration (issue 12: 1 mm)
SWEEP_STEP = math.radians(2.0)  # rad: single-joint sweeps (issue 12: 2 deg steps)
DEPTH_TOL = 0.0005  # m: a flagged IK solution's recorded depth vs MuJoCo's on the kit
PROBE = math.radians(0.5)  # rad: beyond a recorded free end, contact must start within this


class _Model:
    """The kit's MJCF in MuJoCo, and the movable joints of robot.json."""

    def __init__(self, kit: Kit):
        import mujoco

        self.model = mujoco.MjModel.from_xml_path(str(kit.path(kit.mjcf)))
        self.data = mujoco.MjData(self.model)
        self.joints = [
            j for j in kit.joints if j["type"] in ("revolute", "continuous", "prismatic")
        ]
        self.names = [j["name"] for j in self.joints]
        self.adr = sc.joint_addresses(self.model, self.names)
        home = kit.doc.get("home")
        self.home = [float(v) for v in home] if home else [0.0] * len(self.names)
        mimic = {
            j["name"]: (j["mimic"]["joint"], j["mimic"]["multiplier"], j["mimic"]["offset"])
            for j in self.joints
            if j.get("mimic")
        }
        #: mimic joints move with their leaders (the MJCF's equality constraints)
        self.mimics = sc.mimics_of(self.names, mimic)
        self.followers = {self.names[f] for f, *_ in self.mimics}

    def worst(self, q) -> sc.Contact | None:
        return sc.worst(self.model, self.data, self.adr, [float(v) for v in q], self.mimics)


def _deg(q) -> str:
    return "(" + ", ".join(f"{math.degrees(float(v)):.1f}" for v in q) + ") deg"


def _over(label: str, configs: list[tuple[str, list[float]]], m: _Model) -> Finding:
    """One finding for a set of named configurations: the deepest penetration among them."""
    bad = []
    for name, q in configs:
        hit = m.worst(q)
        if hit is not None and hit.depth > TOLERANCE:
            bad.append((hit.depth, name, q, hit))
    if not bad:
        return Finding(
            f"self_collision.{label}",
            True,
            f"{len(configs)} configurations free",
            f"<= {TOLERANCE * 1000:g}",
            "0",
            "",
            "mm",
        )
    depth, name, q, hit = max(bad, key=lambda b: b[0])
    return Finding(
        f"self_collision.{label}",
        False,
        f"{len(bad)} of {len(configs)} configurations collide; worst {name} {_deg(q)}: "
        f"{hit.body1} and {hit.body2} penetrate {depth * 1000:.1f} mm",
        f"<= {TOLERANCE * 1000:g}",
        f"{depth * 1000:.3g}",
        "",
        "mm",
    )


def _poses(kit: Kit, m: _Model) -> list[Finding]:
    poses = kit.doc.get("poses") or {"home": m.home}
    return [_over("poses", [(f"pose '{k}'", v) for k, v in sorted(poses.items())], m)]


def _ik_cases(kit: Kit, m: _Model) -> list[Finding]:
    """Seeds and expected solutions free; a colliding listed solution carries
    `self_collision: true` and its depth, and an unflagged one is free."""
    ref = kit.doc.get("ik_reference")
    if ref is None:
        return []
    doc = json.loads(kit.path(ref["file"]).read_text(encoding="utf-8"))
    free = []
    for case in doc["cases"]:
        free.append((f"{case['name']} seed", case["seed"]["q"]))
        free.append((f"{case['name']} expected", case["expected"]["q"]))
    out = [_over("ik_cases", free, m)]
    wrong = []
    flagged = 0
    for case in doc["cases"]:
        for i, sol in enumerate(case["all_solutions"]):
            hit = m.worst(sol["q"])
            depth = 0.0 if hit is None else hit.depth
            where = f"{case['name']} all_solutions[{i}] {_deg(sol['q'])}"
            if sol.get("self_collision"):
                flagged += 1
                recorded = float(sol.get("self_collision_depth_m", -1.0))
                if abs(recorded - depth) > DEPTH_TOL:
                    wrong.append(
                        f"{where}: recorded depth {recorded * 1000:.2f} mm, MuJoCo "
                        f"{depth * 1000:.2f} mm"
                    )
            elif depth > TOLERANCE:
                wrong.append(
                    f"{where}: {hit.body1} and {hit.body2} penetrate "
                    f"{depth * 1000:.1f} mm, not flagged self_collision"
                )
    detail = (
        f"listed solutions: {flagged} flagged self_collision with their depth, the rest free"
        if not wrong
        else f"{len(wrong)} listed solution(s) wrong: {wrong[0]}"
    )
    out.append(require("self_collision.ik_flags", not wrong, detail))
    return out


def _trapezoids(q0, q1, accel, duration: float, dt: float) -> np.ndarray:
    """Samples of one rest-to-rest move: every joint a trapezoid at its acceleration, all
    ending together after `duration` (robot.json benchmarks.profile)."""
    tau = np.arange(round(duration / dt)) * dt
    out = np.empty((len(tau), len(q0)))
    for j, (a, b, acc) in enumerate(zip(q0, q1, accel, strict=True)):
        dist, sign = abs(b - a), np.sign(b - a)
        disc = max(acc**2 * duration**2 - 4.0 * acc * dist, 0.0)
        v = (acc * duration - math.sqrt(disc)) / 2.0 if dist > 0 else 0.0
        ramp = v / acc
        back = np.clip(duration - tau, 0.0, None)
        pos = np.where(
            tau < ramp,
            0.5 * acc * tau**2,
            np.where(
                tau < duration - ramp,
                0.5 * acc * ramp**2 + v * (tau - ramp),
                dist - 0.5 * acc * back**2,
            ),
        )
        out[:, j] = a + sign * pos
    return out


def _benchmark(kit: Kit, m: _Model) -> list[Finding]:
    """Every sample of the 1 kg cycle (the CSV) and of the rated cycle (its waypoints from the
    CSV, its accelerations and segment times from robot.json)."""
    bench = kit.doc.get("benchmarks")
    if bench is None:
        return []
    files = bench["trajectory_files"]["cycle_1kg"]
    with kit.path(files["csv"]).open(encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    cols = [rows[0].index(f"q_{n}") for n in m.names]
    q = np.array([[float(r[c]) for c in cols] for r in rows[1:]])
    out = [_over("benchmark_1kg", [(f"cycle_1kg sample {i}", row) for i, row in enumerate(q)], m)]
    dt = float(files["dt"])
    ends = np.concatenate([[0], np.cumsum(bench["segment_times"]["cycle_1kg"])])
    waypoints = q[np.round(ends / dt).astype(int)]
    accel = bench["acceleration"]["cycle_rated"]["rad_s2"]
    chunks = [
        _trapezoids(a, b, accel, t, dt)
        for (a, b), t in zip(
            itertools.pairwise(waypoints), bench["segment_times"]["cycle_rated"], strict=True
        )
    ]
    rated = np.vstack([*chunks, waypoints[-1:]])
    out.append(
        _over("benchmark_rated", [(f"cycle_rated sample {i}", r) for i, r in enumerate(rated)], m)
    )
    return out


def _published_limits(joint: dict) -> bool:
    marked = set(joint.get("estimated") or [])
    return not marked & {"lower_deg", "upper_deg", "lower", "upper", "limits"}


def _limits(joint: dict) -> tuple[float, float]:
    """robot.json limits (rad or m); a joint without limits (continuous) sweeps one turn."""
    lower, upper = joint.get("lower"), joint.get("upper")
    return (
        -math.pi if lower is None else float(lower),
        math.pi if upper is None else float(upper),
    )


def _sweeps(kit: Kit, m: _Model) -> list[Finding]:
    """Each joint lower -> upper in 2 deg steps, the others at home (mimic joints with
    their leaders)."""
    recorded = {
        r["joint"]: r
        for r in kit.doc.get("geometry", {}).get("self_collision", {}).get("free_ranges", [])
    }
    out = []
    for i, joint in enumerate(m.joints):
        if joint["name"] in m.followers:
            continue  # a mimic joint moves with its leader: swept by the leader's sweep
        lo, hi = _limits(joint)
        note = ""
        if _published_limits(joint) and joint["name"] in recorded:
            rec = recorded[joint["name"]]
            lo, hi = float(rec["lower"]), float(rec["upper"])
            note = " (published limits; sweep over robot.json's recorded free range)"
            out.extend(_probe_record(m, i, joint, lo, hi))
        count = max(1, math.ceil((hi - lo) / SWEEP_STEP))
        configs = []
        for k in range(count + 1):
            q = list(m.home)
            q[i] = lo + (hi - lo) * k / count
            configs.append((f"{joint['name']} sweep at {math.degrees(q[i]):.1f} deg", q))
        finding = _over(f"sweep.{joint['name']}", configs, m)
        out.append(
            Finding(
                finding.check,
                finding.ok,
                finding.detail + note,
                finding.expected,
                finding.actual,
                finding.tolerance,
                finding.unit,
            )
        )
    return out


def _probe_record(m: _Model, i: int, joint: dict, lo: float, hi: float) -> list[Finding]:
    """A recorded free end inside the published limits must be where contact starts."""
    out = []
    lower, upper = _limits(joint)
    for end, limit, sign in ((lo, lower, -1.0), (hi, upper, 1.0)):
        if abs(end - limit) < 1e-9:
            continue
        q = list(m.home)
        q[i] = end + sign * min(PROBE, abs(limit - end))
        hit = m.worst(q)
        out.append(
            require(
                f"self_collision.free_range.{joint['name']}",
                hit is not None and hit.depth > TOLERANCE,
                f"robot.json free range ends at {math.degrees(end):.1f} deg; contact beyond it: "
                + (
                    "none"
                    if hit is None
                    else f"{hit.body1} and {hit.body2} {hit.depth * 1000:.2f} mm"
                ),
            )
        )
    return out


def check_self_collision(kit: Kit) -> list[Finding]:
    """Named poses, IK cases, both benchmark cycles and single-joint sweeps are free."""
    m = _Model(kit)
    return [*_poses(kit, m), *_ik_cases(kit, m), *_benchmark(kit, m), *_sweeps(kit, m)]
