"""Canonical JSON: floats through the one formatter, 2-space indent, sorted nothing (keys keep
the emitter's deliberate order), trailing newline."""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from simkit.kitio.fmt import rounded


def _clean(value: Any) -> Any:
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return rounded(float(value))
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_clean(v) for v in value]
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def dumps(value: Any) -> bytes:
    """Stable JSON bytes for kit files."""
    return (json.dumps(_clean(value), indent=2, ensure_ascii=False) + "\n").encode("utf-8")
