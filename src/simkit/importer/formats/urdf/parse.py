"""The URDF reader: a `.urdf` file (or a xacro's expansion) parsed into a `Source`.

The XML is parsed with lxml (no entities, no network); a misplaced declaration and content
after the root element are read leniently. In a `.urdf`, `$(arg)`, `$(optenv)`, `$(env)`
and `$(find)` left unexpanded are expanded as xacro would (only names --allow-env gives read
the environment).
"""

from __future__ import annotations

import os

from simkit.errors import SpecError
from simkit.importer.read import lenient
from simkit.importer.read.lenient import Position
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.source import Source
from simkit.spec.urdf_blocks import TAGS  # kept verbatim (formats/urdf/blocks.py)


def read(shell: Source, options: ReadOptions) -> Source:
    """`shell` (path and PackageMap, no root yet) with its `.urdf` parsed, leftover
    substitutions expanded."""
    document(shell, shell.path.read_bytes())
    _expand_leftovers(shell, options)
    return shell


def document(shell: Source, text: bytes) -> Source:
    """`shell` with its root parsed from `text`, which must be a `<robot>`."""
    shell.root = _parse(shell, text)
    if shell.root.tag != "robot":
        raise shell.fail(shell.root, "the root element must be <robot>")
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
