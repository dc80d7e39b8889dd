"""Every value of a source model node (importer/read/model.py), with where it is: the
reader tests' check that each number is a plain float and each source line what the
format gives (the three readers that build the model: MJCF, SDFormat, USD)."""

from __future__ import annotations

import dataclasses


def values(node, path: str = "robot"):
    """(path, value) of every number and every source line (`...sourceline`, None
    included) of `node`, depth first; names and flags left out."""
    if dataclasses.is_dataclass(node):
        for f in dataclasses.fields(node):
            if f.compare:  # not the robot's name index
                yield from values(getattr(node, f.name), f"{path}.{f.name}")
    elif isinstance(node, (tuple, list)):
        for i, item in enumerate(node):
            yield from values(item, f"{path}[{i}]")
    elif not isinstance(node, (str, bool, type(None))) or path.endswith("sourceline"):
        yield path, node


def numbers(node) -> list[tuple[str, object]]:
    """(path, value) of every number of `node`, source lines left out."""
    return [(p, v) for p, v in values(node) if not p.endswith("sourceline")]
