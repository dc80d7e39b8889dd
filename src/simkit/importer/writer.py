"""The spec as YAML: the report as a comment header, then the spec, deterministic."""

from __future__ import annotations

from pathlib import Path

import yaml


class _Dumper(yaml.SafeDumper):
    """Flow style for short number lists (xyz, rgba), block style for the rest."""


def _list(dumper: yaml.SafeDumper, data: list) -> yaml.Node:
    flow = all(isinstance(v, (int, float)) for v in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


def _dict(dumper: yaml.SafeDumper, data: dict) -> yaml.Node:
    flow = all(isinstance(v, (int, float, str)) for v in data.values()) and len(data) <= 6
    return dumper.represent_mapping("tag:yaml.org,2002:map", data.items(), flow_style=flow)


def _str(dumper: yaml.SafeDumper, data: str) -> yaml.Node:
    """Literal block style for multi-line text (an XML block of `urdf_blocks`), so the spec
    shows it as the URDF had it; PyYAML falls back to quoting where a block cannot hold it."""
    style = "|" if "\n" in data else None
    return dumper.represent_scalar("tag:yaml.org,2002:str", data, style=style)


_Dumper.add_representer(str, _str)
_Dumper.add_representer(list, _list)
_Dumper.add_representer(tuple, _list)
_Dumper.add_representer(dict, _dict)


def spec_yaml(spec: dict, lines: list[str], source: Path) -> str:
    """The spec text: a header naming the source and each report line, then the spec."""
    from simkit.kitio.oneline import one_line  # a name holding a newline stays a comment

    head = [
        f"# Imported from {one_line(source.name)} by `simkit import`. Numbers are the URDF's; "
        "values it",
        "# lacks are filled, listed under `estimated` and reported here:",
    ]
    head += [f"#   {one_line(line)}" for line in lines] or ["#   (nothing estimated or left out)"]
    body = yaml.dump(spec, Dumper=_Dumper, sort_keys=False, width=100, allow_unicode=False)
    return "\n".join(head) + "\n" + body


def check(path: Path) -> None:
    """Load the written spec through simkit's own validation (SpecError on a problem)."""
    from simkit.spec.validate import load_spec

    load_spec(path, display=str(path))
