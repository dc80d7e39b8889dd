"""The MJCF reader: a MuJoCo model file compiled by MuJoCo itself (issue 31).

MuJoCo is the reader (`MjSpec.from_file`, then the compiled `MjModel`), so defaults and
classes, `<include>`, meshdir/texturedir/assetdir, mesh scale, `autolimits`, angle units,
`frame` and `childclass` resolve exactly as the simulator resolves them.

The file is untrusted: before MuJoCo sees it, every file it names (`<include>`, a mesh,
texture, hfield or skin `file`, the compiler's folders) is checked to resolve inside the
model's folder, and the files' sizes and the element count are capped; a refusal is one line
naming the file, the line and the element. The files read are kept (`MjcfSource.files`,
paths relative to the model's folder) with their bytes, for the kept source and its digests
(kept.py).
"""

from __future__ import annotations

import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from simkit.errors import SpecError
from simkit.importer.read.lenient import Position
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.source import Source

#: bytes of one XML file (the main model or an include)
MAX_XML = 8 * 1024 * 1024
#: bytes of one asset file (mesh, texture) and of all files together
MAX_ASSET = 64 * 1024 * 1024
MAX_TOTAL = 512 * 1024 * 1024
#: XML elements over the model and its includes; includes; compiled bodies and joints
MAX_ELEMENTS = 50_000
MAX_INCLUDES = 64
MAX_BODIES = 1_000
#: attributes naming a file (texture cube faces included)
FILE_ATTRS = ("file", "fileback", "filedown", "filefront", "fileleft", "fileright", "fileup")
DIR_ATTRS = ("meshdir", "texturedir", "assetdir")


@dataclass
class MjcfSource(Source):
    """A read MJCF: the compiled `model` (mujoco.MjModel) and its `spec` (mujoco.MjSpec);
    `files`: every file it read, relative to the model's folder -> bytes. `robot` is set
    by tree.py: the source model (read/model.py) the shared translation takes."""

    model: object = None
    spec: object = None
    files: dict[str, bytes] = field(default_factory=dict)
    #: (what, reason) of each element a kit cannot carry (listed.py)
    listed: list[tuple[str, str]] = field(default_factory=list)
    #: (kind, compiled id) -> line in the model file of each body, geom, jnt and site
    #: (`lines`): the report's records name it
    lines: dict[tuple[str, int], int] = field(default_factory=dict)
    #: the keys of `lines` that are an `<include>`'s line (shared by what it brings in)
    included: set[tuple[str, int]] = field(default_factory=set)


def read(shell: Source, options: ReadOptions) -> MjcfSource:
    """`shell`'s file checked (confined, bounded) and compiled by MuJoCo; one line on any
    problem (file, line, element)."""
    source = MjcfSource(shell.path, None, shell.packages, shell.report)
    folder = shell.path.resolve().parent
    allowed = [folder, *(p.resolve() for p in options.allow_read)]
    source.files, included = _confined(shell.path.resolve(), folder, allowed)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        source.spec, source.model = _compile(shell.path)
    source.lines, source.included = lines(source.spec, source.model, included)
    for warning in caught:  # MuJoCo's own warnings (a deprecated attribute): one line each
        source.note(Position("mujoco", None), f"MuJoCo: {' '.join(str(warning.message).split())}")
    if source.model.nbody > MAX_BODIES:
        raise SpecError(str(shell.path), None, "mujoco", f"over {MAX_BODIES} bodies")
    return source


def _parse(path: Path, data: bytes, where: tuple[str, int | None]):
    """The lxml root of an MJCF file: no entities, no network, no huge trees."""
    from lxml import etree

    parser = etree.XMLParser(
        remove_comments=True, resolve_entities=False, no_network=True, huge_tree=False
    )
    try:
        return etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise SpecError(
            str(path), exc.lineno or where[1], "xml", f"malformed XML: {exc.msg}"
        ) from None


def _inside(path: Path, folders: list[Path]) -> bool:
    real = path.resolve()
    return any(real == f or f in real.parents for f in folders)


#: MjSpec element lists and the compiled kind (MjModel accessor) of each
KINDS = (("bodies", "body"), ("geoms", "geom"), ("joints", "jnt"), ("sites", "site"))
#: compiled id -> body id, per kind (a nameless element in an include takes its body's line)
BODY_OF = {"geom": "geom_bodyid", "jnt": "jnt_bodyid", "site": "site_bodyid"}


def lines(
    spec, model, included: dict[tuple[str, str], int]
) -> tuple[dict[tuple[str, int], int], set[tuple[str, int]]]:
    """(kind, compiled id) -> line in the model file, and the keys whose line is an
    `<include>`'s. MuJoCo's parser records each element's line (`info`, "line N"), but 0 for
    one read from an `<include>`: that one gets the line of the `<include>` in the model file
    that brought its name in (`included`, by tag and name), else its body's line."""
    tags = {"body": "body", "geom": "geom", "jnt": "joint", "site": "site"}
    out: dict[tuple[str, int], int] = {}
    shared: set[tuple[str, int]] = set()
    for listed, kind in KINDS:
        for element in getattr(spec, listed):
            found = re.fullmatch(r"line (\d+)", element.info or "")
            line = int(found.group(1)) if found else 0
            if not line and (tags[kind], element.name) in included:
                line = included[(tags[kind], element.name)]
                shared.add((kind, int(element.id)))
            if line and element.id >= 0:
                out[(kind, int(element.id))] = line
    for kind, body_of in BODY_OF.items():
        for i in range(int(getattr(model, f"n{kind}"))):
            body = ("body", int(getattr(model, body_of)[i]))
            if (kind, i) not in out and body in out:
                out[(kind, i)] = out[body]
                if body in shared:
                    shared.add((kind, i))
    return out, shared


def _confined(
    main: Path, folder: Path, allowed: list[Path]
) -> tuple[dict[str, bytes], dict[tuple[str, str], int]]:
    """Every file the model names, checked to lie inside `allowed` (the model's folder and
    --allow-read folders) and under the caps, read once: relative path -> bytes; and each
    named element of an included file, (tag, name) -> the line of the `<include>` in the
    model file that brings it in."""
    files: dict[str, bytes] = {}
    included: dict[tuple[str, str], int] = {}
    total = [0]
    roots: list[tuple[Path, object]] = []
    count = 0
    pending = [(main, (str(main), None), None)]
    while pending:
        path, where, top = pending.pop(0)  # top: the model file's <include> line, if any
        data = _read(path, where, MAX_XML, folder, allowed, files, total)
        root = _parse(path, data, where)
        roots.append((path, root))
        for element in root.iter() if top else ():
            if isinstance(element.tag, str) and element.get("name"):
                included.setdefault((element.tag, element.get("name")), top)
        count += sum(1 for _ in root.iter())
        if count > MAX_ELEMENTS:
            raise SpecError(str(path), None, "xml", f"over {MAX_ELEMENTS} elements")
        for inc in root.iter("include", "model"):
            name = inc.get("file")
            if name is None:
                continue
            if len(roots) + len(pending) >= MAX_INCLUDES:
                raise SpecError(str(path), inc.sourceline, inc.tag, f"over {MAX_INCLUDES} includes")
            pending.append(
                (
                    _within(folder / name, path, inc, allowed),
                    (str(path), inc.sourceline),
                    top or inc.sourceline,
                )
            )
    dirs = {""}
    for path, root in roots:
        for compiler in root.iter("compiler"):
            for attr in DIR_ATTRS:
                if compiler.get(attr):
                    _within(folder / compiler.get(attr), path, compiler, allowed, attr)
                    dirs.add(compiler.get(attr))
    for path, root in roots:
        for element in root.iter():
            if not isinstance(element.tag, str) or element.tag in ("include", "model"):
                continue
            for attr in FILE_ATTRS:
                name = element.get(attr)
                if not name:
                    continue
                found = [_within(folder / d / name, path, element, allowed, attr) for d in dirs]
                for candidate in found:
                    if candidate.is_file():
                        _read(candidate, (str(path), element.sourceline), MAX_ASSET, folder,
                              allowed, files, total)  # fmt: skip
    return files, included


def _within(candidate: Path, path: Path, element, allowed: list[Path], attr: str = "file") -> Path:
    """`candidate` when it resolves inside an allowed folder, else one line at `element`."""
    if not _inside(candidate, allowed):
        raise SpecError(
            str(path), element.sourceline, f"{element.tag}.{attr}",
            f"'{element.get(attr)}' lies outside the model's folder (pass --allow-read DIR)",
        )  # fmt: skip
    return candidate.resolve()


def _read(path, where, cap: int, folder: Path, allowed, files: dict, total: list) -> bytes:
    """A file's bytes under `cap` and the running total, kept in `files` by its path
    relative to the model's folder."""
    file, line = where
    try:
        size = path.stat().st_size
        if size > cap or total[0] + size > MAX_TOTAL:
            raise SpecError(file, line, "file", f"'{path.name}' is over {cap // 2**20} MiB")
        data = path.read_bytes()
    except OSError as exc:
        raise SpecError(file, line, "file", f"cannot read '{path.name}': {exc.strerror}") from None
    total[0] += size
    try:
        rel = path.relative_to(folder).as_posix()
    except ValueError:
        rel = path.as_posix()  # an --allow-read folder
    files[rel] = data
    return data


def _compile(path: Path):
    """(MjSpec, MjModel) of the file, or one line with MuJoCo's own message (its line)."""
    import mujoco

    try:
        spec = mujoco.MjSpec.from_file(str(path))
        model = spec.compile()
    except Exception as exc:  # mujoco raises ValueError; bad input may raise others
        text = " ".join(str(exc).split()) or type(exc).__name__
        found = re.search(r"line (\d+)", text)
        element = re.search(r"Element '([^']+)'", text)
        raise SpecError(
            str(path), int(found.group(1)) if found else None,
            element.group(1) if element else "mujoco", f"MuJoCo cannot compile it: {text[:300]}",
        ) from None  # fmt: skip
    return spec, model
