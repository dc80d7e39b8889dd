"""What every format's source proof shares: robot.json's listed differences (`Allowed`),
the tolerances, and the identity of the given source file (`digest`): the kept copy, or
the original the user imported."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.errors import SimkitError
from simkit.kitio.fmt import ZERO_BELOW
from simkit.kitio.oneline import one_line

#: relative tolerance: the kit carries 10 significant digits (kitio/fmt.py); a hand-typed
#: source rarely more. Far below any real change (an axis turned, a mass 10 % off).
REL = 1e-6
#: m: absolute floor for lengths
ABS_LENGTH = 1e-9
#: kg m^2: an inertia tensor's tolerance is REL x its Frobenius norm (a norm, not the
#: principal moments or axes: two nearly equal moments leave the axes ill-defined, the tensor
#: not) plus the writer's zero floor: kitio/fmt writes any term below ZERO_BELOW (1e-12) as
#: 0, so a product of inertia that small is not carried (fingertips of 1e-7 kg m^2 whose
#: frame is turned a little from their principal axes).
INERTIA_FLOOR = ZERO_BELOW


def inertia_close(a, b) -> bool:
    """Two inertia tensors (3x3, kg m^2, the same link axes) agree: every term within
    REL x the source tensor's Frobenius norm + INERTIA_FLOOR."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return bool(np.max(np.abs(a - b)) <= REL * float(np.linalg.norm(a)) + INERTIA_FLOOR)


#: failures named per finding category before "and N more"
SHOWN = 20


def unlisted_findings(check: str, problems: list[str], ok: str) -> list[Finding]:
    """One failing finding per problem the kit's `source_differences` does not list (at most
    `SHOWN`, then "and N more"), or one passing finding saying `ok`: every format's proof
    reports its differences this way."""
    if not problems:
        return [require(check, True, ok)]
    out = [require(check, False, p + " (not listed in source_differences)") for p in problems]
    if len(out) > SHOWN:
        out = [*out[:SHOWN], require(check, False, f"and {len(out) - SHOWN} more")]
    return out


def vector_text(values) -> str:
    """A vector in a finding, six significant digits: `(1, 0.5, 2)`."""
    return "(" + ", ".join(f"{float(v):.6g}" for v in np.ravel(values)) + ")"


@dataclass
class Allowed:
    """robot.json's `source_differences`: allowed keys and the source -> kit renames."""

    keys: set[str] = field(default_factory=set)
    links: dict[str, str] = field(default_factory=dict)
    joints: dict[str, str] = field(default_factory=dict)

    @staticmethod
    def of(doc: dict) -> Allowed:
        """From robot.json (or any dict with `source_differences`)."""
        out = Allowed()
        for item in doc.get("source_differences", []):
            what = str(item.get("what", ""))
            out.keys.add(what)
            kind, _, rest = what.partition(".")
            name, _, attr = rest.rpartition(".")
            if attr == "name" and isinstance(item.get("kit"), str) and kind in ("links", "joints"):
                getattr(out, kind)[name] = item["kit"]
        return out


def digest(kit: Kit, path: Path, remake) -> tuple[list[Finding], bytes]:
    """The given file is the one the import kept (robot.json `source.sha256`) or the one
    the user imported (`source.original`: a URDF or xacro, made into the kept file again by
    `remake(path, args)`, which must give the kept digest). Returns the finding and the
    bytes to compare the kit with (the given file's, unless it is the original)."""
    recorded = kit.doc.get("source") or {}
    data = path.read_bytes()
    actual = hashlib.sha256(data).hexdigest()
    kept, original = recorded.get("sha256"), recorded.get("original")
    if kept is None:
        return [], data
    if actual == kept:
        said = f"{path.name} is the file the import recorded (sha256 {kept[:12]}...)"
        return [require("source.digest", True, said)], data
    if actual != original:
        said = (
            f"{path.name} was changed after the import: sha256 {actual[:12]}..., robot.json "
            f"records {kept[:12]}...{f' (the original {original[:12]}...)' if original else ''}"
        )
        return [require("source.digest", False, said)], data
    try:
        made = remake(path, dict(recorded.get("args") or {}))
    except SimkitError as exc:
        said = f"{path.name} is the imported file, but it no longer reads: {exc}"
        return [require("source.digest", False, one_line(said))], data
    if hashlib.sha256(made).hexdigest() != kept:
        said = (
            f"{path.name} is the imported file (sha256 {actual[:12]}...), but it does not read "
            "as the import read it (a file it includes, or the environment, changed)"
        )
        return [require("source.digest", False, said)], data
    said = (
        f"{path.name} is the file the user imported (sha256 {actual[:12]}...); read as the "
        f"import read it, it gives the kept file (sha256 {kept[:12]}...)"
    )
    return [require("source.digest", True, said)], made
