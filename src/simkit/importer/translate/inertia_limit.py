"""An inertia exactly on the triangle-inequality limit (a flat plate: Ixx + Iyy = Izz), which
MuJoCo refuses once rounding puts A + B a hair below C, is raised off the limit on import.

Every principal moment is raised by NUDGE x the largest (the tensor plus that times the
identity): A + B - C grows by the same amount, far above round-off and far below any
measurement (a part's inertia is rarely known to 1 %). Marked estimated and reported.
"""

from __future__ import annotations

import numpy as np

from simkit.importer.diagnostics import Report
from simkit.importer.read.model import At
from simkit.importer.read.source import Source
from simkit.spec.schema import InertiaSpec
from simkit.spec.validate import mujoco_refuses

#: relative to the largest principal moment
NUDGE = 1e-6
KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")


def nudge(source: Source, element: At | None, out: dict, report: Report) -> None:
    """Raise `out["inertia"]` (a spec inertia dict, kg m^2) off the limit when it is physical
    within the spec's tolerance but MuJoCo refuses it; one report line at `element` (the
    source's inertia)."""
    inertia = out["inertia"]
    values = [float(inertia.get(k, 0.0)) for k in KEYS]
    tensor = np.array(
        [
            [values[0], values[3], values[4]],
            [values[3], values[1], values[5]],
            [values[4], values[5], values[2]],
        ]
    )
    a, b, c = sorted(np.linalg.eigvalsh(tensor))
    if a <= 0 or a + b < c * (1 - 1e-9) or not mujoco_refuses(InertiaSpec(**inertia)):
        return  # not on the limit (fine, or not physical: inertia_decision's business)
    delta = float(f"{NUDGE * c:.3g}")
    for key in KEYS[:3]:
        inertia[key] = round(float(inertia.get(key, 0.0)) + delta, 15)
    out["estimated"] = sorted({*out.get("estimated", []), "inertia"})
    report.estimated(
        source,
        element,
        f"inertia on the triangle-inequality limit ({a:.6g} + {b:.6g} = {c:.6g} kg m^2), which "
        f"MuJoCo refuses after rounding: every principal moment raised by {delta:g} kg m^2",
    )
