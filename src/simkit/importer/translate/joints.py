"""A source model joint (a URDF `<joint>`) to a spec joint: type, origin, axis, limits,
dynamics, mimic."""

from __future__ import annotations

import math

from simkit.importer.diagnostics import Report
from simkit.importer.read.model import Joint
from simkit.importer.read.source import Source
from simkit.importer.translate.geometry import placed
from simkit.spec.bounds import FIELD_BOUNDS, TURNS

TYPES = {"revolute", "continuous", "prismatic", "fixed", "floating"}
#: rad/s and m/s given to a joint without a velocity limit
VELOCITY = {"revolute": 3.0, "continuous": 3.0, "prismatic": 0.5}
G = 9.81


def joint_spec(source: Source, joint: Joint, report: Report, load: tuple[float, float]) -> dict:
    """The spec dict of one joint (a source model `Joint`). `load` = (mass, lever arm in m)
    of what it carries, for an effort the source does not give."""
    kind = joint.type
    if kind == "planar":
        raise source.fail(joint.at, "planar joints are not supported")
    if kind not in TYPES:
        raise source.fail(joint.at, f"unknown joint type '{kind}'")
    if not joint.parent or not joint.child:
        raise source.fail(joint.at, "a joint needs <parent link=...> and <child link=...>")
    for element in joint.unknown:
        report.dropped(source, element, f"not {source.a_noun} joint element simkit keeps")
    spec: dict = {
        "name": joint.name,
        "type": kind,
        "parent": joint.parent,
        "child": joint.child,
        **placed(joint.origin.xyz, joint.origin.rpy),
    }
    if kind in ("fixed", "floating"):
        return spec
    axis = (1.0, 0.0, 0.0) if joint.axis is None else joint.axis
    if math.sqrt(sum(a * a for a in axis)) < 1e-9:
        raise source.fail(joint.axis_at, "joint axis must not be zero")
    spec["axis"] = list(axis)
    limit_at = None if joint.limit is None else joint.limit.at
    if kind == "revolute" and _unbounded(joint):
        kind = spec["type"] = "continuous"
        report.changed(
            source,
            limit_at,
            f"revolute limits beyond {TURNS} turns (a placeholder for none, e.g. a rotor): "
            "imported as continuous",
        )
    elif kind == "revolute" and _reversed(joint):
        kind = spec["type"] = "continuous"
        source.lenient(
            limit_at, "lower > upper, which Bullet reads as no limit: imported as continuous"
        )
    estimated: list[str] = []
    spec.update(_limits(source, joint, kind, report, load, estimated))
    dynamics = joint.dynamics
    if dynamics is not None:
        for key in ("damping", "friction"):
            value = getattr(dynamics, key) or 0.0
            if value < 0:
                raise source.fail(dynamics.at, f"{key} must be >= 0, got {value}")
            if value:
                spec[key] = value
    mimic = joint.mimic
    if mimic is not None:
        if not mimic.joint:
            raise source.fail(mimic.at, "mimic needs a 'joint'")
        spec["mimic"] = {
            "joint": mimic.joint,
            "multiplier": mimic.multiplier,
            "offset": mimic.offset,
        }
        spec["actuated"] = False  # it follows its leader (MJCF equality), no servo of its own
    if estimated:
        spec["estimated"] = estimated
    return spec


def _limits(
    source: Source, joint: Joint, kind: str, report: Report, load: tuple[float, float], estimated
) -> dict:
    limit = joint.limit
    out: dict = {}
    element = limit.at if limit is not None else joint.at
    if kind != "continuous":
        lower = None if limit is None else limit.lower
        upper = None if limit is None else limit.upper
        same = lower is not None and upper is not None and lower == upper
        if _reversed(joint):  # a prismatic one (a revolute one became continuous)
            source.lenient(element, "lower > upper, which Bullet reads as no limit")
        if (lower is None and upper is None) or same or _reversed(joint):
            span = math.pi if kind == "revolute" else 0.1
            unit = "rad" if kind == "revolute" else "m"
            why = "lower == upper (no range)" if same else "no position limits"
            report.estimated(source, element, f"{why}: +-{span:g} {unit}")
            out["lower"], out["upper"] = -span, span
            estimated += ["lower", "upper"]
        else:
            out["lower"] = 0.0 if lower is None else lower
            out["upper"] = 0.0 if upper is None else upper
            if out["lower"] > out["upper"]:
                raise source.fail(element, f"lower ({out['lower']}) is greater than upper")
    velocity = 0.0 if limit is None or limit.velocity is None else limit.velocity
    if velocity < 0 or velocity > FIELD_BOUNDS["max_velocity"][1]:  # -1, 1000: no real limit
        report.estimated(
            source, element, f"velocity {velocity:g} is a placeholder: {VELOCITY[kind]:g}"
        )
        velocity = 0.0
        estimated.append("max_velocity")
    if velocity <= 0:
        velocity = VELOCITY[kind]
        if "max_velocity" not in estimated:
            report.estimated(source, element, f"no velocity limit: {velocity:g}")
            estimated.append("max_velocity")
    out["max_velocity"] = velocity
    effort = 0.0 if limit is None or limit.effort is None else limit.effort
    if effort < 0 or effort > FIELD_BOUNDS["effort_peak"][1]:  # -1, 1e30: no real limit
        report.estimated(source, element, f"effort {effort:g} is a placeholder")
        effort = 0.0
    if effort <= 0:
        mass, arm = load
        effort = float(f"{max(1.0, 2.0 * mass * G * (1.0 if kind == 'prismatic' else arm)):.3g}")
        report.estimated(
            source,
            element,
            f"no effort limit: {effort:g}, twice the static load of what it carries",
        )
        estimated.append("effort_peak")
    out["effort_peak"] = effort
    return out


def _unbounded(joint: Joint) -> bool:
    """A revolute joint whose lower or upper limit lies beyond TURNS turns (a multirotor's
    rotors give +-1e16): the source's way of saying it has none."""
    limit = joint.limit
    if limit is None:
        return False
    return any(v is not None and abs(v) > TURNS * 2 * math.pi for v in (limit.lower, limit.upper))


def _reversed(joint: Joint) -> bool:
    """A `<limit>` whose lower exceeds its upper (a corpus cube: 1 > -1; one not given reads
    0): Bullet reads it as no limit."""
    limit = joint.limit
    if limit is None:
        return False
    return (limit.lower or 0.0) > (limit.upper or 0.0)


def mimic_limits(source: Source, joint: dict, leader: dict, report: Report) -> None:
    """A mimic follower whose limits do not hold its leader's range mapped through the mimic
    (a parallel gripper's finger follower: multiplier -1 on a 0..0.548 leader, limits
    0..0.548) gets that mapped range as its limits, marked estimated and reported: the
    URDF's limits contradict its own mimic (any opening puts the follower out of range), and
    the MJCF's equality would fight the follower's limit."""
    keys = ("lower", "upper")
    if any(k not in joint or k not in leader for k in keys):
        return  # continuous (no limits): nothing to contradict
    m = joint["mimic"]
    lower, upper = sorted(m["multiplier"] * leader[k] + m["offset"] for k in keys)
    tol = 1e-9 * max(1.0, abs(lower), abs(upper))
    if lower >= joint["lower"] - tol and upper <= joint["upper"] + tol:
        return
    found = source.robot.joint(joint["name"])
    report.estimated(
        source,
        source.robot.at if found is None else found.at,
        f"limits {joint['lower']:g}..{joint['upper']:g} do not hold the range of its mimic "
        f"('{m['joint']}' {leader['lower']:g}..{leader['upper']:g} x {m['multiplier']:g} + "
        f"{m['offset']:g}): {lower:g}..{upper:g}",
    )
    joint["lower"], joint["upper"] = lower, upper
    done = joint.get("estimated", [])
    joint["estimated"] = [*done, *(k for k in keys if k not in done)]


def first_leaders(source: Source, joints: list[dict], report: Report) -> None:
    """A mimic of a mimic (an underactuated finger's tip following its middle joint, which
    follows the knuckle) is rewritten to follow the first leader directly: f = a g + b and
    g = c h + d give f = (a c) h + (a d + b), the same motion. URDF readers differ on such
    chains (yourdfpy takes the middle joint's own configuration value, not its mimicked
    one), so every kit file names a driven leader. A chain that loops is dropped (the joints
    move independently). One report line per rewritten joint."""
    by_name = {j["name"]: j for j in joints}
    for joint in joints:
        mimic, seen = joint.get("mimic"), {joint["name"]}
        if mimic is None or "mimic" not in by_name.get(mimic["joint"], {}):
            continue
        multiplier, offset, leader = mimic["multiplier"], mimic["offset"], mimic["joint"]
        while "mimic" in by_name[leader] and leader not in seen:
            seen.add(leader)
            step = by_name[leader]["mimic"]
            multiplier, offset = (
                multiplier * step["multiplier"],
                multiplier * step["offset"] + offset,
            )
            leader = step["joint"]
        found = source.robot.joint(joint["name"])
        element = found.mimic.at if found is not None and found.mimic else source.robot.at
        if leader in seen:
            del joint["mimic"]
            joint.pop("actuated", None)
            report.dropped(source, element, f"mimic chain loops back to '{leader}': independent")
            continue
        report.changed(
            source,
            element,
            f"mimic of '{mimic['joint']}', itself a mimic: follows '{leader}' x {multiplier:g} "
            f"+ {offset:g} (the same motion)",
        )
        joint["mimic"] = {**mimic, "joint": leader, "multiplier": multiplier, "offset": offset}
