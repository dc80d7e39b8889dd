"""Generated code, config and paths: what a user runs or unpacks must parse and stay inside.

- every `.py` parses (`ast.parse`), every `.yaml`/`.rviz` loads (`yaml.safe_load`);
- every file under the kit folder is a plain file or folder that resolves inside it (no
  symlink, no path leaving the kit), and every path robot.json names stays inside;
- the kit's zip beside the folder (`NAME-sim-kit.zip`, as a build writes it) holds exactly the
  kit's files under one top folder `NAME_description/`, byte for byte, with no absolute or
  `..` entry: kit and zip come from one build.
"""

from __future__ import annotations

import ast
import os
from pathlib import Path

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit
from simkit.kitio import layout
from simkit.kitio.kitread import inside

YAML_SUFFIXES = (".yaml", ".yml", ".rviz")


def kit_files(root: Path) -> tuple[dict[str, Path], list[str]]:
    """(relative POSIX path -> file, problems): plain files under `root`; symlinks, special
    files and anything resolving outside `root` are problems, never followed."""
    files: dict[str, Path] = {}
    problems: list[str] = []
    top = root.resolve()
    for folder, dirs, names in os.walk(root, followlinks=False):
        for name in sorted(dirs + names):
            path = Path(folder) / name
            rel = path.relative_to(root).as_posix()
            if path.is_symlink():
                problems.append(f"{rel} is a symlink (to {os.readlink(path)})")
            elif not path.resolve().is_relative_to(top):
                problems.append(f"{rel} resolves outside the kit")
            elif name in names and not path.is_file():
                problems.append(f"{rel} is not a regular file")
            elif name in names:
                files[rel] = path
        dirs[:] = [d for d in dirs if not (Path(folder) / d).is_symlink()]
    return files, problems


def _syntax(files: dict[str, Path]) -> list[Finding]:
    import yaml

    bad_py, bad_yaml = [], []
    py = sorted(rel for rel in files if rel.endswith(".py"))
    cfg = sorted(rel for rel in files if rel.endswith(YAML_SUFFIXES))
    for rel in py:
        try:
            ast.parse(files[rel].read_bytes(), filename=rel)
        except (SyntaxError, ValueError) as exc:
            bad_py.append(f"{rel}: {' '.join(str(exc).split())}")
    for rel in cfg:
        try:
            yaml.safe_load(files[rel].read_bytes())
        except yaml.YAMLError as exc:
            bad_yaml.append(f"{rel}: {' '.join(str(exc).split())[:200]}")
    return [
        require(
            "generated.python",
            not bad_py,
            f"{len(py) - len(bad_py)}/{len(py)} Python files parse (ast.parse)"
            + (f"; {'; '.join(bad_py[:3])}" if bad_py else ""),
        ),
        require(
            "generated.yaml",
            not bad_yaml,
            f"{len(cfg) - len(bad_yaml)}/{len(cfg)} YAML files load (yaml.safe_load)"
            + (f"; {'; '.join(bad_yaml[:3])}" if bad_yaml else ""),
        ),
    ]


def _named_paths(kit: Kit) -> list[str]:
    """Paths robot.json's `files` names that would leave the kit."""
    named = kit.doc.get("files", {})
    values = [v for v in named.values() if isinstance(v, str)] if isinstance(named, dict) else []
    return [v for v in values if not inside(v)]


def _zip(kit: Kit, files: dict[str, Path]) -> list[Finding]:
    """The zip beside the kit holds the same files, under the kit's top folder."""
    import zipfile

    path = kit.root.parent / layout.zip_name(kit.name)
    if not path.is_file():
        return []
    top = layout.kit_dir_name(kit.name)
    problems: list[str] = []
    try:
        with zipfile.ZipFile(path) as archive:
            infos = [i for i in archive.infolist() if not i.is_dir()]
            entries = {}
            for info in infos:
                rel = info.filename.removeprefix(f"{top}/")
                if not info.filename.startswith(f"{top}/") or not inside(rel):
                    problems.append(f"entry {info.filename!r} leaves {top}/")
                elif info.flag_bits & 0x1:
                    problems.append(f"entry {info.filename!r} is encrypted")
                elif rel in files and info.file_size != files[rel].stat().st_size:
                    problems.append(f"{rel} differs in size from the kit's")
                else:
                    entries[rel] = info
            for rel in sorted(set(entries) & set(files)):
                if archive.read(entries[rel]) != files[rel].read_bytes():
                    problems.append(f"{rel} differs from the kit's")
    except (zipfile.BadZipFile, OSError) as exc:
        problems.append(f"unreadable zip: {exc}")
        entries = {}
    missing = sorted(set(files) - set(entries))
    extra = sorted(set(entries) - set(files))
    problems += [f"{rel} is not in the zip" for rel in missing[:3]]
    problems += [f"{rel} is in the zip only" for rel in extra[:3]]
    return [
        require(
            "generated.zip",
            not problems,
            f"{path.name} holds the kit's {len(files)} files under {top}/, byte for byte"
            + (f"; {'; '.join(problems[:3])}" if problems else ""),
        )
    ]


def check_generated(kit: Kit) -> list[Finding]:
    """Parse generated code and config; keep every file and zip entry inside the kit."""
    files, problems = kit_files(kit.root)
    problems += [f"robot.json names {p!r}, outside the kit" for p in _named_paths(kit)]
    findings = [
        require(
            "generated.paths",
            not problems,
            f"{len(files)} plain files, all inside the kit"
            + (f"; {'; '.join(problems[:3])}" if problems else ""),
        )
    ]
    return findings + _syntax(files) + _zip(kit, files)
