"""Read a URDF or xacro file and resolve its mesh URIs (package://, file://, relative).

Errors are one line each, naming the file, the line and the element (`errors.SpecError`).
Messy but common forms are read leniently, one report line each (`Source.lenient`), and
refused with `--strict` (docs/importing.md, "Lenient reading"). The report is the one
diagnostic channel of the read (Drake's DiagnosticPolicy); a PackageMap owns paths.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer import lenient
from simkit.importer.lenient import Position
from simkit.importer.packages import MissingMesh, PackageMap
from simkit.importer.reading import ReadOptions

__all__ = [
    "MissingMesh", "Position", "ReadOptions", "Source",
    "describe", "line_of", "load", "resolve_uri",
]  # fmt: skip


@dataclass
class Source:
    """The parsed document: its root element, where it came from, how to find packages,
    and the report its lenient readings go to (None: refuse them)."""

    path: Path
    root: object  # lxml.etree._Element
    packages: PackageMap
    report: object | None = None  # importer.report.Report

    def fail(self, element, message: str) -> SpecError:
        """A one-line error at `element` (file, line, element tag and name)."""
        return SpecError(str(self.path), line_of(element), describe(element), message)

    def lenient(self, element, message: str) -> None:
        """A form read the way the field's parsers read it: one report line (changed), or
        the error `--strict` asks for."""
        if self.report is None or self.report.strict:
            raise self.fail(element, f"{message} (--strict refuses it)")
        self.report.changed(self, element, message)

    def note(self, element, message: str) -> None:
        """A report line for something the user asked for (a --xacro-arg value used)."""
        if self.report is not None:
            self.report.changed(self, element, message)


def line_of(element) -> int | None:
    """Source line of an lxml element (None when unknown)."""
    line = getattr(element, "sourceline", None)
    return int(line) if line else None


def describe(element) -> str:
    """`tag` or `tag[name]` (URDF elements are named by their `name` attribute)."""
    if element is None:
        return "robot"
    name = element.get("name") if hasattr(element, "get") else None
    return f"{element.tag}[{name}]" if name else str(element.tag)


def load(
    path: Path,
    package_dirs: tuple[Path, ...] = (),
    report=None,
    options: ReadOptions | None = None,
) -> Source:
    """Parse a `.urdf` (or expand a `.xacro`, safely unless trusted); `report` takes the
    lenient readings (None: they are refused, as with --strict)."""
    options = options or ReadOptions()
    if not path.is_file():
        raise SpecError(str(path), None, "file", "no such file")
    packages = PackageMap(path, tuple(package_dirs), tuple(options.allow_read))
    shell = Source(path, None, packages, report)
    if path.suffix == ".xacro" or path.name.endswith(".urdf.xacro"):
        from simkit.importer.xacro_safe import expand

        text = expand(path, packages, options, shell)
    else:
        text = path.read_bytes()
    shell.root = _parse(shell, text)
    if shell.root.tag != "robot":
        raise shell.fail(shell.root, "the root element must be <robot>")
    if not path.name.endswith(".xacro"):
        _expand_leftovers(shell, options)
    return shell


def _parse(source: Source, text: bytes):
    """The lxml root of `text`; a misplaced or odd declaration and content after the root
    element are read leniently."""
    from lxml import etree

    text, notes = lenient.fix_declaration(text)
    for line, message in notes:
        source.lenient(Position("xml", line), message)
    parser = etree.XMLParser(remove_comments=True, resolve_entities=False, no_network=True)
    try:
        return etree.fromstring(text, parser)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if exc.lineno else None
        error = SpecError(str(source.path), line, "xml", f"malformed XML: {exc.msg}")
        if "Extra content at the end" not in exc.msg or not line:
            raise error from None
        cut = lenient.cut_trailing(text, line, exc.position[1])
    try:
        root = etree.fromstring(cut, parser)
    except etree.XMLSyntaxError:
        raise error from None
    source.lenient(
        Position("xml", line), f"content after the root element's end ignored (line {line})"
    )
    return root


def _expand_leftovers(source: Source, options: ReadOptions) -> None:
    """`$(arg)`, `$(optenv)`, `$(env)` and `$(find)` left unexpanded in a .urdf's links and
    joints: expanded to the --xacro-arg value or the default (the environment only where
    --allow-env names it). Gazebo, transmission and ros2_control blocks stay verbatim."""
    defaults = {
        e.get("name"): e.get("default")
        for e in source.root.iter()
        if isinstance(e.tag, str) and e.tag.rpartition("}")[2] == "arg" and e.get("name")
    }
    from simkit.spec.urdf_blocks import TAGS  # kept verbatim (importer/blocks.py)

    given = options.args()
    core = [e for e in source.root if isinstance(e.tag, str) and e.tag not in TAGS]
    for element in (d for e in core for d in e.iter()):
        if not isinstance(element.tag, str):
            continue
        for key, value in element.attrib.items():
            if "$(" in value:
                element.set(
                    key,
                    lenient.substitute(value, _resolver(source, element, given, defaults, options)),
                )


def _resolver(source: Source, element, given: dict, defaults: dict, options: ReadOptions):
    def resolve(command: str, args: list[str]) -> str:
        name = args[0] if args else ""
        if command == "arg" and name in given:
            source.note(element, f"$(arg {name}): '{given[name]}' (--xacro-arg)")
            return given[name]
        if command == "arg" and defaults.get(name) is not None:
            source.lenient(
                element, f"$(arg {name}) left in a .urdf: its default '{defaults[name]}'"
            )
            return defaults[name]
        if command == "arg":
            raise source.fail(
                element, f"$(arg {name}) has no value: pass --xacro-arg {name}:=VALUE"
            )
        if command in ("env", "optenv") and name in options.allow_env and name in os.environ:
            value = os.environ[name]
            source.note(element, f"$({command} {name}): '{value}' (--allow-env)")
            return value
        if command == "optenv" and name:
            default = " ".join(args[1:])
            source.lenient(
                element,
                f"$(optenv {name}) left in a .urdf: its default '{default}' (the environment "
                "is read only for names given with --allow-env)",
            )
            return default
        if command == "env":
            raise source.fail(element, f"$(env {name}) refused: pass --allow-env {name} to read it")
        if command == "find" and name:
            source.lenient(element, f"$(find {name}) left in a .urdf: read as package://{name}")
            return f"package://{name}"
        raise source.fail(element, f"unknown substitution $({command} {' '.join(args)})")

    return resolve


def resolve_uri(source: Source, element, uri: str) -> Path:
    """The file a mesh `filename` names (PackageMap); each fallback is one report line.
    MissingMesh when no file is found, SpecError when refused or ambiguous."""
    done = len(source.packages.notes)
    where = (str(source.path), line_of(element), describe(element))
    path = source.packages.resolve(uri, where)
    for message in source.packages.notes[done:]:
        source.note(element, message)
    return path
