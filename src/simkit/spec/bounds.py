"""Physical plausibility bounds: refuse values no robot can have before any step runs.

Without them an absurd value is refused only by running out the clock or the memory (joint
limits of 1e9 deg make the IK enumerate every 2 pi multiple; 1e12 kg breaks the servo
tuning; a 2 MB title is laid out by matplotlib). The bounds are generous for any arm, leg
or gripper (units SI, as the spec fields): a value outside them is a typo.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from simkit.spec.load import Loc

Problem = tuple[Loc, str]

TURNS = 2  # joint limits and poses of revolute joints: at most this many turns either way
MAX_TITLE = 200
MAX_TEXT = 5000  # description, notes
MAX_STRING = 500  # any other string (sources, plugin names, estimated fields, ...)
MAX_BLOCK = 20000  # one carried URDF block (`urdf_blocks`: a Gazebo plugin's XML)
MAX_ANY = 1e6  # any other number
MAX_BODIES = 10000  # links, joints, frames: an import is near-linear in them (performance.md)
MAX_ITEMS = 1000  # any other list

#: field name -> (low, high, unit) on its absolute value; low applies to non-zero values only
#: where the field may be zero by default.
FIELD_BOUNDS: dict[str, tuple[float, float, str]] = {
    "mass": (1e-4, 1e4, "kg"),
    "ixx": (0.0, 1e4, "kg m^2"),
    "iyy": (0.0, 1e4, "kg m^2"),
    "izz": (0.0, 1e4, "kg m^2"),
    "ixy": (0.0, 1e4, "kg m^2"),
    "ixz": (0.0, 1e4, "kg m^2"),
    "iyz": (0.0, 1e4, "kg m^2"),
    "xyz": (0.0, 100.0, "m"),
    "com": (0.0, 100.0, "m"),
    "from": (0.0, 100.0, "m"),
    "to": (0.0, 100.0, "m"),
    "pos": (0.0, 100.0, "m"),
    "size": (0.0, 100.0, "m"),
    "radius": (1e-3, 100.0, "m"),
    "radius_top": (0.0, 100.0, "m"),
    "length": (1e-3, 100.0, "m"),
    "scale": (1e-4, 1e4, ""),
    "rpy": (0.0, 2 * TURNS * math.pi, "rad"),
    "rpy_deg": (0.0, 360.0 * TURNS, "deg"),
    "max_velocity": (0.0, 200.0, "rad/s or m/s"),
    "max_velocity_deg_s": (0.0, 12000.0, "deg/s"),
    "effort_peak": (0.0, 1e5, "N m or N"),
    "effort_continuous": (0.0, 1e5, "N m or N"),
    "drive_peak_torque_at_joint": (0.0, 1e5, "N m"),
    "motor_peak_torque": (0.0, 1e4, "N m"),
    "gear_max_output_torque": (0.0, 1e5, "N m"),
    "gear_ratio": (0.0, 1e4, ""),
    "rotor_inertia": (0.0, 10.0, "kg m^2"),
    "gear_inertia": (0.0, 10.0, "kg m^2"),
    "armature": (0.0, 100.0, "kg m^2"),
    "damping": (0.0, 1e5, "N m s/rad"),
    "friction": (0.0, 1e5, "N m"),
    "stiffness": (0.0, 1e6, "N m/rad"),
    "kp": (0.0, 1e7, "N m/rad"),
    "kv": (0.0, 1e6, "N m s/rad"),
    "timestep": (1e-5, 0.05, "s"),
    "duration": (0.0, 30.0, "s"),
    "update_rate": (0.0, 1e5, "Hz"),
    "offwidth": (0.0, 8192, "px"),
    "offheight": (0.0, 8192, "px"),
    "seed": (0.0, 2**32 - 1, ""),
}

#: fields checked elsewhere in this module (they depend on the joint type)
_SKIP = {"lower", "upper", "lower_deg", "upper_deg", "poses", "poses_deg"}
_MULTILINE = {"description", "note"}


def _number(loc: Loc, value: float) -> str | None:
    field = next((str(p) for p in reversed(loc) if isinstance(p, str)), "")
    low, high, unit = FIELD_BOUNDS.get(field, (0.0, MAX_ANY, ""))
    size = abs(value)
    unit = f" {unit}" if unit else ""
    if size > high:
        return f"{value:g}{unit} is beyond what a robot can have (at most {high:g}{unit})"
    if low and size < low and (size > 0 or field in ("mass", "radius", "length", "timestep")):
        return f"{value:g}{unit} is too small to simulate (at least {low:g}{unit})"
    if field == "size" and 0 < size < 1e-3:
        return f"{value:g} m is too small to simulate (at least 0.001 m)"
    return None


def _string(loc: Loc, value: str) -> str | None:
    field = next((str(p) for p in reversed(loc) if isinstance(p, str)), "")
    cap = MAX_TITLE if field == "title" else MAX_TEXT if field in _MULTILINE else MAX_STRING
    cap = MAX_BLOCK if field == "urdf_blocks" else cap
    if len(value) > cap:
        return f"at most {cap} characters (this has {len(value)})"
    allowed = "\n\t" if field == "urdf_blocks" else "\n" if field in _MULTILINE else ""
    if any(not (c.isprintable() or c in allowed) for c in value):
        return "control characters are not allowed" + (
            "" if allowed else " (one line of printable text)"
        )
    return None


def _walk(value: object, loc: Loc) -> Iterator[Problem]:
    if isinstance(value, dict):
        for key, item in value.items():
            if not loc and key in _SKIP:
                continue
            if len(loc) == 2 and loc[0] == "joints" and key in _SKIP:
                continue
            yield from _walk(item, (*loc, key))
    elif isinstance(value, (list, tuple)):
        cap = MAX_BODIES if loc in (("links",), ("joints",), ("frames",)) else MAX_ITEMS
        if len(value) > cap:
            yield loc, f"at most {cap} entries (this has {len(value)})"
            return
        for i, item in enumerate(value):
            yield from _walk(item, (*loc, i))
    elif isinstance(value, bool) or value is None:
        return
    elif isinstance(value, (int, float)):
        why = _number(loc, float(value))
        if why:
            yield loc, why
    elif isinstance(value, str):
        why = _string(loc, value)
        if why:
            yield loc, why


def _joint_range(spec) -> Iterator[Problem]:
    for i, joint in enumerate(spec.joints):
        for key in ("lower", "upper", "lower_deg", "upper_deg"):
            value = getattr(joint, key)
            if value is None:
                continue
            if joint.type == "prismatic":
                if abs(value) > 100.0:
                    yield ("joints", i, key), f"{value:g} is beyond a prismatic travel of 100 m"
                continue
            rad = math.radians(value) if key.endswith("_deg") else value
            if abs(rad) > 2 * math.pi * TURNS * (1 + 1e-12):
                yield ("joints", i, key), f"{value:g} is beyond {TURNS} turns of a revolute joint"


def _poses(spec) -> Iterator[Problem]:
    for key, scale in (("poses", 1.0), ("poses_deg", math.pi / 180)):
        if len(getattr(spec, key)) > MAX_ITEMS:
            yield (key,), f"at most {MAX_ITEMS} poses"
            continue
        for pose, values in getattr(spec, key).items():
            for k, value in enumerate(values):
                if abs(value * scale) > max(2 * math.pi * TURNS, 100.0) * (1 + 1e-12):
                    yield (key, pose, k), f"{value:g} is beyond any joint's travel"


def problems(spec) -> Iterator[Problem]:
    """Every value outside the plausibility bounds, in spec order."""
    yield from _walk(spec.model_dump(by_alias=True), ())
    yield from _joint_range(spec)
    yield from _poses(spec)
