"""The tolerances of `simkit diff`: one rule per quantity, the tolerance the checks use for it.

A difference below the tolerance that `simkit check` allows for a quantity is round-off, not a
change (issue 23). tests/test_diff.py asserts that each constant equals its check's constant.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator

#: m: lengths, positions, CoM (check/urdf.py TOL, check/mujoco.py PARAM_TOL,
#: check/geometry.py CONVEX_TOL: float32 STL round-off on a face plane)
LENGTH_M = 1e-6
#: rad: angles, limits and origins' rpy (check/urdf.py TOL "rad or m")
ANGLE_RAD = 1e-6
#: kg (check/mujoco.py mass.mjcf, mass.urdf)
MASS_KG = 1e-6
#: kg m^2 (check/mujoco.py inertia.urdf_vs_mjcf)
INERTIA_KG_M2 = 1e-7
#: speeds, efforts, damping, friction, armature, gains, unitless numbers (PARAM_TOL "SI")
PARAM_SI = 1e-6
#: relative: every written number carries 10 significant digits (kitio/fmt.py)
REL = 1e-9
#: STEP solids are compared in mm (diff/step.py): the length rule in mm and mm^3
STEP_LENGTH_MM = LENGTH_M * 1000

#: tolerance by unit, for robot.json fields
BY_UNIT = {"m": LENGTH_M, "rad": ANGLE_RAD, "kg": MASS_KG, "kg m^2": INERTIA_KG_M2}

NUMBER = re.compile(rb"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def tolerance(unit: str) -> float:
    """The absolute tolerance for a quantity in `unit` (PARAM_SI where no rule is closer)."""
    return BY_UNIT.get(unit, PARAM_SI)


def is_number(value: object) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def close(a: float, b: float, tol: float) -> bool:
    """|a - b| within `tol` plus the 10-digit round-off; non-finite values only equal
    themselves (NaN equals NaN here: the file did not change)."""
    a, b = float(a), float(b)
    if not (math.isfinite(a) and math.isfinite(b)):
        return (math.isnan(a) and math.isnan(b)) or a == b
    return abs(a - b) <= tol + REL * max(abs(a), abs(b))


def same(a: object, b: object, tol: float) -> bool:
    """Two JSON values equal, numbers within `tol`."""
    return next(leaf_changes(a, b, tol), None) is None


def leaf_changes(a: object, b: object, tol: float, path: str = "") -> Iterator[tuple]:
    """(path, old, new) for every leaf of two JSON values that differs beyond `tol`; a list
    of another length or a value of another type is one leaf."""
    if is_number(a) and is_number(b):
        if not close(a, b, tol):
            yield path, a, b
    elif isinstance(a, dict) and isinstance(b, dict):
        for key in [*a, *(k for k in b if k not in a)]:
            sub = f"{path}.{key}" if path else str(key)
            if key not in a or key not in b:
                yield sub, a.get(key), b.get(key)
            else:
                yield from leaf_changes(a[key], b[key], tol, sub)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            yield from leaf_changes(x, y, tol, f"{path}[{i}]")
    elif a != b:
        yield path, a, b


def text_close(a: bytes, b: bytes, tol: float = PARAM_SI) -> bool:
    """Two texts equal but for numbers that differ within `tol`: the same words in the same
    order, each pair of numbers `close` (a kit's URDF, MJCF, SRDF, USD text, README)."""
    if a == b:
        return True
    words_a, words_b = NUMBER.split(a), NUMBER.split(b)
    if words_a != words_b:
        return False
    return all(
        close(float(x), float(y), tol)
        for x, y in zip(NUMBER.findall(a), NUMBER.findall(b), strict=True)
    )


def decimals(tol: float) -> int:
    """Decimal places that resolve `tol`: 1e-6 -> 6, 3e-7 -> 7, 0.05 -> 2."""
    return math.ceil(-math.log10(tol) - 1e-9)


def quantize(value: object, tol: float) -> object:
    """`value` shown at its quantity's tolerance (issue 34): every number rounded to the
    decimal places that resolve `tol`, a number below `tol` 0, lists and dicts element by
    element; words, booleans, integers, non-finite numbers and `tol` <= 0 as they are."""
    if isinstance(value, float) and tol > 0 and math.isfinite(value):
        return 0.0 if abs(value) < tol else round(value, decimals(tol)) + 0.0
    if isinstance(value, (list, tuple)):
        return [quantize(v, tol) for v in value]
    if isinstance(value, dict):
        return {k: quantize(v, tol) for k, v in value.items()}
    return value
