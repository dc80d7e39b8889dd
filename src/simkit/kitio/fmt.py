"""The one number formatter every text output uses, so files are stable byte for byte."""

from __future__ import annotations

import math
from collections.abc import Iterable

SIGNIFICANT_DIGITS = 10
#: Magnitudes below this are round-off (products of inertia of symmetric solids, cos(pi/2)),
#: written as 0 so they do not churn diffs.
ZERO_BELOW = 1e-12


def num(value: float, digits: int = SIGNIFICANT_DIGITS) -> str:
    """Format a float with `digits` significant digits; `-0` is written as `0`.

    Integers that are whole keep no trailing `.0` (``1.0`` -> ``"1"``), as in hand-written XML.
    """
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"cannot format non-finite number {x!r}")
    if abs(x) < ZERO_BELOW:
        return "0"
    text = format(x, f".{digits}g")
    if text in ("-0", "-0.0") or float(text) == 0.0:
        return "0"
    return text


def vec(values: Iterable[float], digits: int = SIGNIFICANT_DIGITS) -> str:
    """Space-separated numbers, the form URDF and MJCF attributes take."""
    return " ".join(num(v, digits) for v in values)


def rounded(value: float, digits: int = SIGNIFICANT_DIGITS) -> float:
    """The float that `num` prints, for JSON output (json writes shortest round-trip reprs)."""
    return float(num(value, digits))
