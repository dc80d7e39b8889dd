"""Read a URDF or xacro file and resolve its mesh URIs (package://, file://, relative).

Errors are one line each, naming the file, the line and the element (`errors.SpecError`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from simkit.errors import SpecError


@dataclass
class Source:
    """The parsed document: its root element, where it came from, and how to find packages."""

    path: Path
    root: object  # lxml.etree._Element
    package_dirs: tuple[Path, ...] = ()
    _packages: dict[str, Path | None] = field(default_factory=dict)

    def fail(self, element, message: str) -> SpecError:
        """A one-line error at `element` (file, line, element tag and name)."""
        return SpecError(str(self.path), line_of(element), describe(element), message)


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


def load(path: Path, package_dirs: tuple[Path, ...] = ()) -> Source:
    """Parse a `.urdf` (or expand a `.xacro` with the xacro package, no ROS needed)."""
    from lxml import etree

    if not path.is_file():
        raise SpecError(str(path), None, "file", "no such file")
    if path.suffix == ".xacro" or path.name.endswith(".urdf.xacro"):
        text = _expand_xacro(path)
    else:
        text = path.read_bytes()
    parser = etree.XMLParser(remove_comments=True, resolve_entities=False)
    try:
        root = etree.fromstring(text, parser)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if exc.lineno else None
        raise SpecError(str(path), line, "xml", f"malformed XML: {exc.msg}") from None
    if root.tag != "robot":
        raise SpecError(str(path), line_of(root), str(root.tag), "the root element must be <robot>")
    return Source(path, root, tuple(package_dirs))


def _expand_xacro(path: Path) -> bytes:
    import xacro

    try:
        doc = xacro.process_file(str(path))
    except Exception as exc:  # xacro raises many types; report one line
        message = " ".join(str(exc).split()) or type(exc).__name__
        raise SpecError(str(path), None, "xacro", f"xacro expansion failed: {message}") from None
    return doc.toxml(encoding="utf-8")


def _package_xml_name(path: Path) -> str | None:
    from lxml import etree

    try:
        name = etree.parse(str(path)).getroot().findtext("name")
    except (OSError, etree.XMLSyntaxError):
        return None
    return name.strip() if name else None


def find_package(source: Source, package: str) -> Path | None:
    """Folder of ROS package `package`: --package-dir, then ROS_PACKAGE_PATH, then the first
    folder above the URDF whose package.xml names it (or that is named after it)."""
    if package in source._packages:
        return source._packages[package]
    found: Path | None = None
    search = list(source.package_dirs) + [
        Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p
    ]
    for base in search:
        for candidate in (base / package, base):
            if (candidate / "package.xml").is_file() and _package_xml_name(
                candidate / "package.xml"
            ) == package:
                found = candidate
                break
            if candidate.name == package and candidate.is_dir():
                found = candidate
                break
        if found:
            break
    if found is None:
        for parent in source.path.resolve().parents:
            xml = parent / "package.xml"
            if (xml.is_file() and _package_xml_name(xml) == package) or parent.name == package:
                found = parent
                break
    source._packages[package] = found
    return found


def resolve_uri(source: Source, element, uri: str) -> Path:
    """The file a mesh `filename` names; one-line error if it cannot be found."""
    if uri.startswith("package://"):
        package, _, rest = uri[len("package://") :].lstrip("/").partition("/")
        base = find_package(source, package) if package else None
        if base is None:
            raise source.fail(element, f"unknown package '{package}' in {uri}")
        path = base / rest
    elif uri.startswith("file://"):
        path = Path(uri[len("file://") :])
    else:
        path = Path(uri)
        if not path.is_absolute():
            path = source.path.parent / path
    if not path.is_file():
        raise source.fail(element, f"mesh file not found: {uri}")
    return path
