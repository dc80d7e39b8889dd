"""Did you mean ...": the field names the schema allows where an unknown key was written."""

from __future__ import annotations

import difflib
import types
import typing
from typing import Any

from pydantic import BaseModel

from simkit.spec.load import Loc


def _leaves(annotation: Any) -> list[Any]:
    """The types an annotation can hold: Annotated, Optional and unions unwrapped."""
    origin = typing.get_origin(annotation)
    if origin is typing.Annotated:
        return _leaves(typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        return [leaf for arg in typing.get_args(annotation) for leaf in _leaves(arg)]
    return [annotation]


def _model(leaf: Any) -> bool:
    return isinstance(leaf, type) and issubclass(leaf, BaseModel)


def _field(model: type[BaseModel], key: str) -> Any:
    for name, info in model.model_fields.items():
        if key in (name, info.alias):
            return info.annotation
    return None


def _step(leaf: Any, part: str | int) -> list[Any]:
    """The types under `leaf` at one step of a field path (a key or an index)."""
    if _model(leaf):
        found = _field(leaf, part) if isinstance(part, str) else None
        return _leaves(found) if found is not None else []
    origin, args = typing.get_origin(leaf), typing.get_args(leaf)
    if origin in (tuple, list) and isinstance(part, int) and args:
        if origin is list or (len(args) == 2 and args[1] is Ellipsis):
            return _leaves(args[0])
        return _leaves(args[part]) if part < len(args) else []
    if origin is dict and isinstance(part, str) and len(args) == 2:
        return _leaves(args[1])
    return []


def allowed_fields(root: type[BaseModel], loc: Loc) -> list[str]:
    """The keys (as written in YAML) the schema takes at `loc`, sorted; [] when unknown."""
    leaves: list[Any] = [root]
    for part in loc:
        leaves = [below for leaf in leaves for below in _step(leaf, part)]
    names = {
        info.alias or name
        for leaf in leaves
        if _model(leaf)
        for name, info in leaf.model_fields.items()
    }
    return sorted(names)


def did_you_mean(root: type[BaseModel], loc: Loc) -> str:
    """` (did you mean 'mass'?)` for an unknown key at `loc`, or "" with no close name."""
    if not loc or not isinstance(loc[-1], str):
        return ""
    close = difflib.get_close_matches(loc[-1], allowed_fields(root, loc[:-1]), n=1, cutoff=0.6)
    return f"; did you mean '{close[0]}'?" if close else ""
