"""Write: the draft's spec as YAML (the report as a comment header, then the spec,
deterministic), validated once, moved into the output folder with its meshes and the kept
source the format wrote into the staging folder (output.py); a refusal names the source
element (located.py)."""

from __future__ import annotations

from pathlib import Path

import yaml

from simkit.importer.draft import Draft
from simkit.importer.write import located
from simkit.importer.write.output import publish
from simkit.kitio.oneline import one_line


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


def spec_yaml(spec: dict, lines: list[str], source: Path, noun: str = "URDF") -> str:
    """The spec text: a header naming the source and each report line, then the spec."""
    head = [
        f"# Imported from {one_line(source.name)} by `simkit import`. Numbers are the {noun}'s; "
        "values it",
        "# lacks are filled, listed under `estimated` and reported here:",
    ]
    head += [f"#   {one_line(line)}" for line in lines] or ["#   (nothing estimated or left out)"]
    body = yaml.dump(spec, Dumper=_Dumper, sort_keys=False, width=100, allow_unicode=False)
    return "\n".join(head) + "\n" + body


def check(path: Path, draft: Draft) -> None:
    """Load the written spec through simkit's own validation; a problem is one line at the
    URDF element its field comes from (write/located.py), never the staging copy."""
    located.check(path, draft.spec, draft.source, draft.renames)


def finish(draft: Draft, out_dir: Path) -> Path:
    """Write the draft's spec once, validate it once (`check`), and copy it with its meshes
    from the staging folder into `out_dir`; a mesh the spec written there before used and
    this one does not is removed (no stale meshes). Returns the spec's path in `out_dir`."""
    name = draft.spec["name"]
    staged = draft.stage / f"{name}.yaml"
    text = spec_yaml(draft.spec, draft.report.lines, draft.path, draft.source.noun)
    staged.write_text(text, encoding="utf-8")
    check(staged, draft)
    target = out_dir / f"{name}.yaml"
    new = {item.relative_to(draft.stage) for item in draft.stage.rglob("*") if item.is_file()}
    others = set().union(*(_meshes_of(p) for p in out_dir.glob("*.yaml") if p != target))
    stale = sorted(_meshes_of(target) - new - others)  # another spec's stay
    publish(draft.stage, out_dir)  # all files whole, or none (output.py): one line naming it
    for old in stale:  # only once the new spec is in place: a failure changes nothing
        (out_dir / old).unlink(missing_ok=True)
    return target


def refuse(draft: Draft) -> None:
    """Raise the draft's first problem where the URDF holds it (located.py): a draft the
    steps cannot resolve (draft.Unresolvable: a mass of 1e308) stops in one line, not deep
    in a fix-up."""
    staged = draft.stage / f"{draft.spec['name']}.yaml"
    text = spec_yaml(draft.spec, draft.report.lines, draft.path, draft.source.noun)
    staged.write_text(text, "utf-8")
    located.check(staged, draft.spec, draft.source, draft.renames)
    raise RuntimeError("a spec the schema refused passed simkit's validation")


def _meshes_of(spec_path: Path) -> set[Path]:
    """The relative mesh files an earlier spec at `spec_path` names (none if unreadable)."""
    try:
        spec = yaml.safe_load(spec_path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError, UnicodeDecodeError):
        return set()
    out: set[Path] = set()
    links = spec.get("links") if isinstance(spec, dict) else None
    for link in links if isinstance(links, list) else []:
        for key in ("solid", "collision_shapes", "collision_primitives"):
            shapes = link.get(key) if isinstance(link, dict) else None
            for shape in shapes if isinstance(shapes, list) else []:
                if isinstance(shape, dict) and isinstance(shape.get("file"), str):
                    rel = Path(shape["file"])
                    if not rel.is_absolute() and ".." not in rel.parts:
                        out.add(rel)
    return out
