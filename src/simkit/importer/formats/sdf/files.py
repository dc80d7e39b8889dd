"""The files an SDFormat import reads, confined: the model file, its `<include>`s and meshes.

The file is untrusted. Every file it names must resolve (symbolic links followed) inside the
model's folder: the Gazebo model folder (the nearest one at or above the file holding a
`model.config`), else the robot's package root (read/packages.py, as for a URDF), or an
`--allow-read` folder. `model://NAME/...` names that folder itself (NAME its folder name)
or a sibling model folder NAME beside it (the model path Gazebo searches), nothing else;
`package://` goes through the PackageMap as for a URDF; http(s) is never fetched. Sizes,
file counts and include depth are capped. A refusal is one line naming the file, the line
and the element. The bytes of every file read are kept (`files`: path relative to the
model path, the model folder's parent), for the kept source (kept.py) and its proof.
"""

from __future__ import annotations

import copy
import os
import re
from pathlib import Path

from simkit.errors import SpecError

MAX_XML = 8 * 1024 * 1024
MAX_FILE = 64 * 1024 * 1024
MAX_TOTAL = 512 * 1024 * 1024
MAX_FILES = 256
MAX_DEPTH = 16
MAX_ELEMENTS = 50_000


def model_folder(path: Path) -> Path | None:
    """The Gazebo model folder of `path` (a folder, or a file in one): the nearest folder at
    or above it holding `model.config` (two levels at most), else None."""
    here = path.resolve() if path.is_dir() else path.resolve().parent
    for folder in (here, here.parent):
        if (folder / "model.config").is_file():
            return folder
    return None


def from_config(folder: Path, where: tuple[str, int | None, str]) -> Path:
    """The SDF a model folder's `model.config` names (its newest `<sdf version>`)."""
    from lxml import etree

    config = folder / "model.config"
    try:
        root = etree.fromstring(config.read_bytes(), _parser())
    except (OSError, etree.XMLSyntaxError) as exc:
        raise SpecError(str(config), None, "model.config", f"cannot read it: {exc}") from None
    named = [(_version(e.get("version")), (e.text or "").strip()) for e in root.iter("sdf")]
    named = [n for n in named if n[1]]
    if not named:
        raise SpecError(str(config), None, "model.config", "names no <sdf> file")
    target = folder / max(named)[1]
    if not _inside(target, [folder]) or not target.is_file():
        raise SpecError(str(config), None, "sdf", f"'{max(named)[1]}' is no file in {folder.name}")
    return target.resolve()


def _version(text: str | None) -> tuple[int, ...]:
    try:
        return tuple(int(v) for v in (text or "0").split("."))
    except ValueError:
        return (0,)


def _parser():
    from lxml import etree

    return etree.XMLParser(
        remove_comments=True, remove_pis=True, resolve_entities=False, no_network=True,
        huge_tree=False,
    )  # fmt: skip


def _inside(path: Path, folders) -> bool:
    real = path.resolve()
    return any(real == f.resolve() or f.resolve() in real.parents for f in folders)


class Files:
    """The confined reader of one import: `folder` (the model folder), `allowed` (it and
    the folders the user allows), `files` (relative path -> bytes), `packages` (a name a
    `model://` or `package://` URI used -> its folder relative to the model path)."""

    def __init__(self, main: Path, folder: Path, packages) -> None:
        self.main, self.folder, self.packages = main.resolve(), folder.resolve(), packages
        self.base = self.folder.parent
        self.files: dict[str, bytes] = {}
        self.named: dict[str, str] = {}
        self.total = 0

    def allowed(self) -> list[Path]:
        return [self.folder, *self.packages.allow_read]

    def key(self, path: Path) -> str:
        return Path(os.path.relpath(path.resolve(), self.base)).as_posix()

    def read(self, path: Path, where: tuple[str, int | None, str], cap: int = MAX_FILE) -> bytes:
        """A confined file's bytes, under the caps, kept in `files`."""
        file, line, element = where
        if not (_inside(path, self.allowed()) or self.packages.allowed(path)):
            raise SpecError(file, line, element, f"'{path}' lies outside the model's folder")
        key = self.key(path)
        if key in self.files:
            return self.files[key]
        try:
            size = path.stat().st_size
            if size > cap or self.total + size > MAX_TOTAL or len(self.files) >= MAX_FILES:
                raise SpecError(file, line, element, f"'{path.name}' is over the size caps")
            data = path.read_bytes()
        except OSError as exc:
            raise SpecError(
                file, line, element, f"cannot read '{path.name}': {exc.strerror}"
            ) from None
        self.total += size
        self.files[key] = data
        return data

    def parse(self, path: Path, where) -> object:
        """The root element of an SDF file (confined, capped, no entities or network)."""
        from lxml import etree

        data = declared(self.read(path, where, MAX_XML))
        try:
            root = etree.fromstring(data, _parser())
        except etree.XMLSyntaxError as exc:
            raise SpecError(str(path), exc.lineno, "xml", f"malformed XML: {exc.msg}") from None
        if sum(1 for _ in root.iter()) > MAX_ELEMENTS:
            raise SpecError(str(path), None, "xml", f"over {MAX_ELEMENTS} elements")
        return root

    def uri(self, text: str, here: Path, where, must_exist: bool = True) -> Path:
        """The file or folder a URI names, written in file `here`; one line when it is
        refused (outside the model's folder, a network URI) or, `must_exist`, not found."""
        file, line, element = where
        text = text.strip()
        scheme = text.split("://", 1)[0].lower() if "://" in text else ""
        if scheme in ("http", "https", "ftp"):
            raise SpecError(file, line, element, f"'{text}' is a network URI: never fetched")
        if scheme == "model":
            name, _, rest = text[len("model://") :].partition("/")
            folder = self._model(name, where)
            path = folder / rest
        elif scheme == "package":
            name, _, rest = text[len("package://") :].partition("/")
            found = self.packages.find(name) if name else None
            if found is None:
                raise SpecError(file, line, element, f"unknown package '{name}' in {text}")
            folder, path = found, found / rest
            self.named.setdefault(name, self.key(found))
        elif scheme in ("", "file"):
            path = Path(text[len("file://") :] if scheme else text)
            path = path if path.is_absolute() else here.parent / path
            folder = None
        else:
            raise SpecError(file, line, element, f"'{text}': unknown URI scheme '{scheme}'")
        inside = _inside(path, [folder]) if folder else False
        if not (inside or _inside(path, self.allowed()) or self.packages.allowed(path)):
            raise SpecError(file, line, element, f"'{text}' lies outside the model's folder")
        if must_exist and not path.exists():
            raise SpecError(file, line, element, f"'{text}': no such file")
        return path.resolve()

    def _model(self, name: str, where) -> Path:
        """The folder `model://NAME` names: the model folder itself, or a sibling model
        folder (one holding model.config) in its parent, the model path."""
        if name == self.folder.name:
            return self.folder
        sibling = self.base / name
        if name not in ("", ".", "..") and "/" not in name and (sibling / "model.config").is_file():
            if not _inside(sibling, [self.base]):
                raise SpecError(*where, f"model://{name} lies outside the model path")
            self.packages.allow_read = (*self.packages.allow_read, sibling.resolve())
            self.named.setdefault(name, self.key(sibling))
            return sibling.resolve()
        raise SpecError(*where, f"model://{name}: no such model beside {self.folder.name}")


def declared(data: bytes) -> bytes:
    """`data` with each element prefix it uses undeclared (`<gz:...>`, `<drake:...>`: SDFormat
    readers ignore namespaces, XML refuses them) declared on the `<sdf>` tag, in its line."""
    used = set(re.findall(rb"</?([A-Za-z_][\w.-]*):[A-Za-z_]", data))
    missing = sorted(used - set(re.findall(rb"xmlns:([A-Za-z_][\w.-]*)\s*=", data)) - {b"xml"})
    if not missing:
        return data
    names = b" ".join(b'xmlns:%s="urn:undeclared:%s"' % (p, p) for p in missing)
    return re.sub(rb"<sdf\b", b"<sdf " + names, data, count=1)


def scrubbed(element, line: int | None):
    """A deep copy of an included element, every line set to the `<include>`'s (its own
    lines are another file's)."""
    out = copy.deepcopy(element)
    for e in out.iter():
        e.sourceline = line or 0
    return out
