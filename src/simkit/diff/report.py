"""The report of `simkit diff`: one `Change` per semantic change, the files added, removed,
changed or changed only by round-off, and the report as strict JSON (`--json`).

Numbers in a `Change` are already shown at the tolerance of their quantity
(`tolerance.quantize`), so the JSON, the Markdown and the HTML print the same values.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field

from simkit.diff.tolerance import PARAM_SI, quantize


@dataclass(frozen=True)
class Change:
    """One semantic change: `kind` is joint, link, mesh, collision, step, usd or robot_json;
    `change` is modified, added or removed. `old` and `new` are kept at `tolerance` (the absolute
    tolerance of the quantity, in `unit`; 0 for counts and words): every number is rounded to
    it and a number below it is 0, so no output can print round-off as a change."""

    kind: str
    name: str
    change: str = "modified"
    field: str = ""
    old: object = None
    new: object = None
    unit: str = ""
    tolerance: float = PARAM_SI

    def __post_init__(self) -> None:
        object.__setattr__(self, "old", quantize(self.old, self.tolerance))
        object.__setattr__(self, "new", quantize(self.new, self.tolerance))


@dataclass
class Report:
    old: str
    new: str
    changes: list[Change] = field(default_factory=list)
    added: list[str] = field(default_factory=list)
    removed: list[str] = field(default_factory=list)
    changed: list[str] = field(default_factory=list)
    #: files whose bytes differ only below the tolerances or in METADATA_KEYS
    round_off: list[str] = field(default_factory=list)
    #: METADATA_KEYS values that changed (paths such as provenance.spec_sha256)
    metadata: list[str] = field(default_factory=list)

    @property
    def equal(self) -> bool:
        """Nothing changed beyond round-off."""
        return not (self.changes or self.added or self.removed or self.changed)

    @property
    def identical(self) -> bool:
        return self.equal and not self.round_off

    def to_json(self) -> str:
        """The report as strict JSON (a NaN or infinity read from a kit becomes a string)."""
        doc = {
            "equal": self.equal,
            "identical": self.identical,
            "old": self.old,
            "new": self.new,
            "changes": [asdict(c) for c in self.changes],
            "files": {
                "added": self.added,
                "removed": self.removed,
                "changed": self.changed,
                "round_off": self.round_off,
            },
            "metadata": self.metadata,
        }
        return json.dumps(_finite(doc), indent=2, allow_nan=False) + "\n"


def _finite(value):
    """`value` with every non-finite float as the string JSON readers know it by."""
    if isinstance(value, float) and not math.isfinite(value):
        return "NaN" if math.isnan(value) else ("Infinity" if value > 0 else "-Infinity")
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    return value
