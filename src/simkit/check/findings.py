"""A finding: one comparison with expected, actual, tolerance and unit."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Finding:
    """Outcome of one check. `actual`/`expected` are already reduced to what was compared."""

    check: str
    ok: bool
    detail: str
    expected: str = ""
    actual: str = ""
    tolerance: str = ""
    unit: str = ""

    def line(self) -> str:
        status = "ok  " if self.ok else "FAIL"
        numbers = ""
        if self.expected or self.actual:
            numbers = f": expected {self.expected}, got {self.actual}"
            if self.tolerance:
                numbers += f" (tolerance {self.tolerance}{' ' + self.unit if self.unit else ''})"
        return f"{status} {self.check}: {self.detail}{numbers}"


def _g(value) -> str:
    arr = np.atleast_1d(np.asarray(value, dtype=float)).ravel()
    text = ", ".join(f"{v:.6g}" for v in arr)
    return text if arr.size == 1 else f"({text})"


def compare(check: str, detail: str, expected, actual, tolerance: float, unit: str) -> Finding:
    """Finding for |expected - actual| <= tolerance, element-wise, reporting the worst error."""
    exp = np.asarray(expected, dtype=float)
    act = np.asarray(actual, dtype=float)
    if exp.shape != act.shape:
        return Finding(check, False, f"{detail}: shape {act.shape} instead of {exp.shape}")
    error = float(np.max(np.abs(exp - act))) if exp.size else 0.0
    ok = bool(np.isfinite(error) and error <= tolerance)
    return Finding(
        check,
        ok,
        f"{detail} (worst error {error:.3g} {unit})".rstrip(),
        _g(exp) if exp.size <= 6 else f"{exp.size} values",
        _g(act) if act.size <= 6 else f"{act.size} values",
        f"{tolerance:g}",
        unit,
    )


def require(check: str, ok: bool, detail: str) -> Finding:
    """A yes/no finding."""
    return Finding(check, bool(ok), detail)
