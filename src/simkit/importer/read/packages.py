"""`package://`, `file://` and relative mesh paths to files: the robot's PackageMap.

After Drake's `PackageMap` (multibody/parsing): one object owns package resolution for a
whole import. The order (docs/importing.md, "Mesh resolution"):

1. `--package-dir`, then `ROS_PACKAGE_PATH`, then the first folder above the URDF whose
   package.xml names the package or that is named after it (today's order, unreported);
2. else the path's tail searched down from the robot's *package root* (the nearest folder
   above the URDF holding a package.xml or .git, else the folder above the URDF's own):
   `a/b/mesh.stl`, then `b/mesh.stl`, then `mesh.stl`, the longest tail that matches wins,
   at most MAX_DEPTH folders down and never above the root. One report line names the file
   chosen; candidates whose bytes differ are an error naming two of them.

A plain path (relative, or absolute `file://`) must lie under the package root, a found
package folder or an `--allow-read` folder (issue 24: a downloaded URDF must not pull any
file on disk into a shareable kit).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from simkit.errors import SpecError

#: folders searched below the package root for a path's tail
MAX_DEPTH = 8
#: files and folders looked at by one tail search index at most (a root such as $HOME)
MAX_ENTRIES = 100_000


class MissingMesh(SpecError):
    """A mesh file that no rule finds (the importer drops that geometry, or --strict refuses)."""


def package_root(urdf: Path) -> Path:
    """The nearest folder at or above `urdf`'s own holding package.xml or .git, else the
    folder above the URDF's own (the common `urdf/` beside `meshes/` layout)."""
    here = urdf.resolve().parent
    for folder in (here, *here.parents):
        if (folder / "package.xml").is_file() or (folder / ".git").exists():
            return folder
    return here.parent


def _package_xml_name(path: Path) -> str | None:
    from lxml import etree

    try:
        parser = etree.XMLParser(resolve_entities=False, no_network=True)
        name = etree.parse(str(path), parser).getroot().findtext("name")
    except (OSError, etree.XMLSyntaxError):
        return None
    return name.strip() if name else None


def _inside(path: Path, folder: Path) -> bool:
    try:
        path.relative_to(folder)
    except ValueError:
        return False
    return True


@dataclass
class PackageMap:
    """Resolves one robot's mesh and include paths; caches each answer (reported once)."""

    urdf: Path
    package_dirs: tuple[Path, ...] = ()
    allow_read: tuple[Path, ...] = ()
    root: Path = field(init=False)
    notes: list[str] = field(default_factory=list)  # one report line per fallback
    _found: dict[str, Path | None] = field(default_factory=dict)
    _index: list[dict[str, list[Path]]] | None = None
    _uris: dict[str, Path | SpecError] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.urdf = self.urdf.resolve()
        self.root = package_root(self.urdf)

    def search_path(self) -> list[Path]:
        """--package-dir folders, then ROS_PACKAGE_PATH's."""
        env = os.environ.get("ROS_PACKAGE_PATH", "")
        return [*self.package_dirs, *(Path(p) for p in env.split(os.pathsep) if p)]

    def find(self, package: str) -> Path | None:
        """Folder of ROS package `package` by today's order (module docstring, step 1)."""
        if package in self._found:
            return self._found[package]
        found: Path | None = None
        for base in self.search_path():
            for candidate in (base / package, base):
                xml = candidate / "package.xml"
                named = xml.is_file() and _package_xml_name(xml) == package
                if named or (candidate.name == package and candidate.is_dir()):
                    found = candidate
                if found:
                    break
            if found:
                break
        if found is None:
            for parent in self.urdf.parents:
                xml = parent / "package.xml"
                if (xml.is_file() and _package_xml_name(xml) == package) or parent.name == package:
                    found = parent
                    break
        self._found[package] = found
        return found

    def allowed(self, path: Path) -> bool:
        """Whether a plain path may be read: under the package root, a found package folder,
        a --package-dir or ROS_PACKAGE_PATH folder, or an --allow-read folder."""
        real = path.resolve()
        folders = [self.root, *self.search_path(), *self.allow_read]
        folders += [p for p in self._found.values() if p is not None]
        return any(_inside(real, Path(f).resolve()) for f in folders)

    def resolve(self, uri: str, where: tuple[str, int | None, str]) -> Path:
        """The file `uri` names. `where` = (file, line, element) for errors. MissingMesh when
        nothing is found, SpecError when refused or ambiguous."""
        if uri not in self._uris:
            try:
                self._uris[uri] = self._resolve(uri, where)
            except SpecError as exc:
                self._uris[uri] = exc
        got = self._uris[uri]
        if isinstance(got, SpecError):
            raise type(got)(where[0], where[1], where[2], got.message)
        return got

    def _resolve(self, uri: str, where: tuple[str, int | None, str]) -> Path:
        file, line, element = where
        if uri.startswith("package://"):
            package, _, rest = uri[len("package://") :].lstrip("/").partition("/")
            base = self.find(package) if package else None
            if base is not None and (base / rest).is_file():
                inside = _inside((base / rest).resolve(), base.resolve())
                if not inside and not self.allowed(base / rest):
                    raise SpecError(
                        file, line, element, f"{uri} climbs out of package '{package}' ({base})"
                    )
                return base / rest
            missing = f"unknown package '{package}' in {uri}" if base is None else None
            parts = [package, *Path(rest).parts]
        else:
            path = Path(uri[len("file://") :] if uri.startswith("file://") else uri)
            if not path.is_absolute():
                path = self.urdf.parent / path
            if path.is_file():
                if not self.allowed(path):
                    raise SpecError(
                        file,
                        line,
                        element,
                        f"{uri} lies outside the robot's package root {self.root} "
                        "(pass --allow-read DIR to allow it)",
                    )
                return path
            missing = None
            parts = [
                p for p in Path(uri.removeprefix("file://")).parts if p not in ("/", ".", "..")
            ]
        found = self._by_tail(parts, uri, where)
        if found is None:
            raise MissingMesh(file, line, element, missing or f"mesh file not found: {uri}")
        return found

    def _by_tail(self, parts: list[str], uri: str, where) -> Path | None:
        """The nearest file whose path ends with the longest tail of `parts`: the URDF's
        folder first, then each folder above it up to the package root."""
        parts = [p for p in parts if p]
        if not parts:
            return None
        for level in self._levels():
            named = level.get(parts[-1], [])
            for k in range(len(parts), 0, -1):
                tail = tuple(parts[-k:])
                hits = sorted(
                    (p for p in named if p.parts[-k:] == tail),
                    key=lambda p: (len(p.parts), p.as_posix()),
                )
                if hits:
                    return self._choose(hits, uri, where)
        return None

    def _choose(self, hits: list[Path], uri: str, where) -> Path:
        first = self.root / hits[0]
        data = first.read_bytes()
        for other in hits[1:]:
            if (self.root / other).read_bytes() != data:
                raise SpecError(
                    where[0],
                    where[1],
                    where[2],
                    f"{uri} is not where it says; two files under the package root match its "
                    f"path and differ: {hits[0].as_posix()} and {other.as_posix()}",
                )
        shown = os.path.relpath(first, self.urdf.parent).replace(os.sep, "/")
        self.notes.append(
            f"{uri} not found as given: using {shown}, found by its path's tail under the "
            "robot's package root"
        )
        return first

    def _levels(self) -> list[dict[str, list[Path]]]:
        """Per folder from the URDF's up to the root: file name -> paths (relative to the
        root) newly under it, MAX_DEPTH deep, no links, no dot folders; MAX_ENTRIES in all."""
        if self._index is not None:
            return self._index
        here = self.urdf.parent
        folders = [here, *(p for p in here.parents if _inside(p, self.root))]
        if not _inside(here, self.root):
            folders = [self.root]
        self._index, seen, done = [], 0, None
        for folder in folders:
            level: dict[str, list[Path]] = {}
            for top, dirs, files in os.walk(folder, followlinks=False):
                depth = len(Path(top).relative_to(folder).parts)
                dirs[:] = sorted(d for d in dirs if not d.startswith(".") and Path(top) / d != done)
                if depth >= MAX_DEPTH:
                    dirs[:] = []
                for name in sorted(files):
                    if not (Path(top) / name).is_symlink():
                        level.setdefault(name, []).append((Path(top) / name).relative_to(self.root))
                seen += len(files) + len(dirs)
                if seen > MAX_ENTRIES:
                    break
            self._index.append(level)
            done = folder
            if seen > MAX_ENTRIES:
                break
        return self._index
