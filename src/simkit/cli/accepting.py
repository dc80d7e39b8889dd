"""`simkit build NAME --accept-published`: write the model's values into the spec's
`published:` block where they disagree, then build as usual.

The model's values come from the check's own computation (`check/published_numbers.py`
`published_values`) on a kit built, unchecked, into a temporary folder: what the published
check will compare is exactly what is written, so the rewritten spec builds green (each value
is written to a hundredth of its tolerance, `spec/published_edit.spelled`).

Only the spec `find_spec` resolves is rewritten: a file the user named, or `robots/NAME.yaml`
of a source checkout named by NAME. A spec inside an installed simkit (a wheel's
`simkit/_data/robots/`) is refused, not edited: it belongs to the installation, and the next
upgrade would put it back; the message says to copy it and build the copy. A symlinked spec is
refused too (the rewrite would land in another file than the one named).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from simkit.errors import SimkitError


def installed_spec(path: Path, robots: Path) -> bool:
    """Whether `path` is a packaged spec of an installed simkit: it lies in `robots`, the
    packaged robots/ folder, and that folder is the wheel's `_data/robots`."""
    return robots.parent.name == "_data" and path.resolve().parent == robots.resolve()


def _writable_spec(target: str) -> Path:
    """The spec file `target` names, if --accept-published may rewrite it."""
    from simkit.kitio.resources import data_dir
    from simkit.pipeline import find_spec

    path, _ = find_spec(target)
    if installed_spec(path, data_dir("robots")):
        raise SimkitError(
            f"{target}: {path} belongs to the installed simkit, so --accept-published does "
            f"not edit it; copy it (cp {path} ./{path.name}) and build the copy: "
            f"simkit build ./{path.name} --accept-published"
        )
    if path.is_symlink():
        raise SimkitError(f"{path}: a symbolic link; --accept-published edits only a plain file")
    return path


def accept_published(target: str, usd_format: str, step: bool, cache) -> list[str]:
    """Rewrite the disagreeing `published:` values of `target`'s spec with the model's;
    returns one line per value changed (`FILE:LINE: published.FIELD: OLD -> NEW`)."""
    from simkit.check.kit import Kit
    from simkit.check.published_numbers import published_values
    from simkit.pipeline import build
    from simkit.spec.published_edit import rewrite_published

    path = _writable_spec(target)
    with tempfile.TemporaryDirectory(prefix="simkit-accept-") as tmp:
        result = build(
            target,
            Path(tmp),
            check=False,
            cache=cache,
            usd_format=usd_format,
            step=step,
            remember=False,
        )
        values = published_values(Kit.open(result.kit_dir))
    wanted: dict[str, tuple] = {}
    for value in values:  # the first computation of a field is the one written
        if not value.ok:
            wanted.setdefault(value.field, (value.model, value.tolerance))
    text = path.read_text(encoding="utf-8")
    shown = str(path) if Path(target).suffix in (".yaml", ".yml") else f"robots/{path.name}"
    new, edits = rewrite_published(text, shown, wanted)
    if not edits:
        return [f"{shown}: published: every figure agrees with the model; the spec is unchanged"]
    _replace(path, new)
    return [f"{shown}:{e.line}: {e.field}: {e.old} -> {e.new}" for e in edits]


def _replace(path: Path, text: str) -> None:
    """Write `text` over `path` atomically (a temporary file beside it, renamed), keeping
    its permission bits: a kill leaves the old spec or the new one, never half of one."""
    mode = path.stat().st_mode & 0o7777
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as handle:
            handle.write(text)
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
