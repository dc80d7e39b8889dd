"""Give an error raised deep inside a derive step the spec's file, line and field.

Derive steps see the resolved model, not the YAML: they raise `SpecError(something, None,
field, message)` with the field they know (`freefall.pose`, `solid.file`, `collision`).
`locate` finds that field in the spec document, so the user still gets `FILE:LINE: field:
message`. Library errors on user input (MuJoCo refusing a degenerate geom, trimesh failing on
a mesh) become one line too (`refusal`).
"""

from __future__ import annotations

import re
from pathlib import Path

from simkit.errors import SpecError
from simkit.spec.load import Loc, SourceDoc, dotted

#: Exceptions a library raises on input it cannot use (not simkit bugs): shown in one line.
LIBRARY_ERRORS: tuple[type[BaseException], ...] = (
    ValueError,
    ArithmeticError,
    RuntimeError,
    NotImplementedError,
    ImportError,
    MemoryError,
    IndexError,
    KeyError,
)


def _parse(field: str) -> Loc:
    """`links[2].solid[0].file` -> ('links', 2, 'solid', 0, 'file')."""
    out: list[str | int] = []
    for name, index in re.findall(r"([^.\[\]]+)|\[(\d+)\]", field):
        out.append(int(index) if index else name)
    return tuple(out)


def _find(exc: SpecError, spec, base_dir: Path) -> Loc | None:
    """Where in the spec the error belongs."""
    loc = _parse(exc.field)
    if loc and loc[0] in type(spec).model_fields:
        return loc
    links = list(spec.links)
    by_name = {link.name: i for i, link in enumerate(links)}
    if exc.field == "solid.file":
        for i, link in enumerate(links):
            for k, prim in enumerate(link.solid):
                if prim.shape != "mesh" or not prim.file:
                    continue
                resolved = str((base_dir / prim.file).resolve())
                if exc.file in (resolved, str(base_dir)) and (
                    exc.file == resolved or prim.file in exc.message
                ):
                    return ("links", i, "solid", k, "file")
    if exc.file in by_name and loc:
        return ("links", by_name[exc.file], *loc)
    return None


def locate(exc: SpecError, doc: SourceDoc, spec, base_dir: Path) -> SpecError:
    """`exc` with the spec's file, line and dotted field where they can be found."""
    if exc.file == doc.file and exc.line is not None:
        return exc
    loc = _find(exc, spec, base_dir)
    if loc is None:
        return SpecError(doc.file, exc.line, exc.field, exc.message, exc.more)
    return SpecError(doc.file, doc.line_of(loc), dotted(loc), exc.message, exc.more)


def refusal(exc: BaseException, doc: SourceDoc) -> SpecError:
    """A library's refusal of this spec's robot as one line naming the spec file."""
    text = " ".join(str(exc).split())[:300] or type(exc).__name__
    return SpecError(doc.file, None, "<robot>", f"cannot build this robot: {text}")
