"""A finding: one comparison with expected, actual, tolerance and unit."""

from __future__ import annotations

from collections.abc import Callable, Sequence
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


#: a vector with more values than this is reported by its worst element (with its label)
SHOWN_VALUES = 6


def _worst(error: np.ndarray) -> tuple[int, ...]:
    """Index of the largest element error (a NaN counts as the largest)."""
    filled = np.where(np.isnan(error), np.inf, error)
    return tuple(int(i) for i in np.unravel_index(int(np.argmax(filled)), error.shape))


def _where(index: tuple[int, ...], labels: Sequence[str] | None) -> str:
    """`J3` (a label for the first axis), `link_2[1]` (and the rest of the index), `[4]`."""
    if labels is not None and index and len(labels) > index[0]:
        rest = index[1:]
        return str(labels[index[0]]) + (f"[{', '.join(map(str, rest))}]" if rest else "")
    return f"[{', '.join(map(str, index))}]"


def compare(
    check: str,
    detail: str,
    expected,
    actual,
    tolerance: float,
    unit: str,
    labels: Sequence[str] | None = None,
) -> Finding:
    """Finding for |expected - actual| <= tolerance, element-wise, reporting the worst error.

    `labels` name the entries along the first axis (joint or link names), so a failure says
    which: up to `SHOWN_VALUES` values are shown whole with the worst one's label; more are
    shown by the worst entry alone, `J3: expected 1.5708, got 1.6 (tolerance 1e-06 rad)`
    (its whole row when that is short, such as a link's CoM)."""
    exp = np.asarray(expected, dtype=float)
    act = np.asarray(actual, dtype=float)
    if exp.shape != act.shape:
        return Finding(check, False, f"{detail}: shape {act.shape} instead of {exp.shape}")
    diff = np.abs(exp - act)
    error = float(np.max(diff)) if exp.size else 0.0
    ok = bool(np.isfinite(error) and error <= tolerance)
    worst = _worst(diff) if exp.size else ()
    where = _where(worst, labels) if exp.size > 1 or labels is not None else ""
    if exp.size <= SHOWN_VALUES:
        at = f" at {where}" if where and exp.size else ""
        shown_exp, shown_act = _g(exp), _g(act)
        detail = f"{detail} (worst error {error:.3g} {unit}{at})".replace(" )", ")")
    else:
        row = worst[:1] if exp.ndim > 1 and exp[worst[:1]].size <= SHOWN_VALUES else worst
        if row is not worst:
            where = _where(row, labels)
        shown_exp, shown_act = _g(exp[row]), _g(act[row])
        detail = f"{detail} (worst error {error:.3g} {unit}, {exp.size} values): {where}"
        detail = detail.replace(" ,", ",")
    return Finding(check, ok, detail, shown_exp, shown_act, f"{tolerance:g}", unit)


def require(check: str, ok: bool, detail: str) -> Finding:
    """A yes/no finding."""
    return Finding(check, bool(ok), detail)


#: failed findings a failed build lists, one per line (`simkit check KIT -v` shows every one)
LISTED_FAILURES = 10


def failure_message(
    robot: str, failed: list[Finding], explain: Callable[[Finding], str | None] | None = None
) -> str:
    """The failed build's message: a head line, then each failure on its own line (up to
    `LISTED_FAILURES`), as `explain` words it (a published figure at its spec line) or as
    its finding line."""
    lines = [f"{robot}: {len(failed)} check(s) failed:"]
    for finding in failed[:LISTED_FAILURES]:
        lines.append("  " + ((explain(finding) if explain else None) or finding.line()))
    if len(failed) > LISTED_FAILURES:
        lines.append(f"  (and {len(failed) - LISTED_FAILURES} more: `simkit check KIT` lists all)")
    return "\n".join(lines)
