"""Every geometry and asset reference in the kit's models resolves inside the kit (issue 24).

A kit is one self-contained download: a URDF mesh at `../../elsewhere/part.stl`, an absolute
MJCF mesh path or a USD asset on the builder's disk would load on the builder's machine and
nowhere else (or pull a private file into someone else's scene). Read as the engines read
them, independently of the emitters:

- URDF: `<mesh filename>` of links' visuals and collisions and `<texture filename>` of
  materials: relative to the URDF's folder,
  `package://PKG/...` with PKG the kit's own package, or `file://` (absolute);
- MJCF: `file` of `mesh`, `texture`, `hfield`, `skin` and `include`, under the compiler's
  `meshdir`/`texturedir`/`assetdir`, relative to the MJCF's folder;
- SDFormat: every `<uri>`, relative to the SDF's folder (`file://` absolute);
- USD: every asset and layer path pxr reports (`UsdUtils.ComputeAllDependencies`);
- glTF binary: `uri` of buffers and images that are not `data:` URIs.

Blocks copied verbatim from an imported URDF (`<gazebo>`, `<transmission>`, `<ros2_control>`)
may name other packages (`$(find other_pkg)`): they are listed as external references, not
failures.
"""

from __future__ import annotations

import json
import re
import struct
import xml.etree.ElementTree as ET
from pathlib import Path

from simkit.check.findings import Finding, require
from simkit.check.kit import Kit

#: URDF blocks kept as the source wrote them (spec/urdf_blocks.py)
COPIED_BLOCKS = ("gazebo", "transmission", "ros2_control")
MJCF_FILES = {"mesh": "meshdir", "skin": "meshdir", "hfield": "assetdir", "texture": "texturedir"}
EXTERNAL = re.compile(r"\$\(find [^)]+\)|package://[^\s<\"']+|model://[^\s<\"']+")


def _inside(kit: Kit, target: Path) -> bool:
    try:
        return target.resolve().is_relative_to(kit.root.resolve())
    except (OSError, ValueError):
        return False


def _uri(kit: Kit, base: Path, uri: str) -> Path | None:
    """The file a URI or path names, or None for a package other than the kit's own."""
    if uri.startswith("package://"):
        package, _, rest = uri[len("package://") :].partition("/")
        return kit.root / rest if package == kit.root.name else None
    if uri.startswith("file://"):
        return Path(uri[len("file://") :])
    return base / uri


def _urdf(kit: Kit, path: Path) -> tuple[list[tuple[str, Path | None]], list[str]]:
    """(reference, resolved file) of every link mesh; external references of copied blocks."""
    root = ET.parse(path).getroot()
    named = [mesh for link in root.iter("link") for mesh in link.iter("mesh")]
    named += [tex for top in root if top.tag not in COPIED_BLOCKS for tex in top.iter("texture")]
    refs = [(e.get("filename", ""), _uri(kit, path.parent, e.get("filename", ""))) for e in named]
    own = (f"$(find {kit.root.name})", f"package://{kit.root.name}/")
    external = [
        found
        for block in root
        if block.tag in COPIED_BLOCKS
        for found in EXTERNAL.findall(ET.tostring(block, encoding="unicode"))
        if not found.startswith(own)
    ]
    return refs, external


def _mjcf(kit: Kit, path: Path) -> list[tuple[str, Path | None]]:
    root = ET.parse(path).getroot()
    dirs = {key: "" for key in ("meshdir", "texturedir", "assetdir")}
    for compiler in root.iter("compiler"):
        dirs.update({k: v for k, v in compiler.attrib.items() if k in dirs})
    refs = []
    for element in root.iter():
        if element.tag == "include" and element.get("file"):
            refs.append((element.get("file"), path.parent / element.get("file")))
        elif element.tag in MJCF_FILES and element.get("file"):
            folder = dirs[MJCF_FILES[element.tag]] or dirs["assetdir"]
            refs.append((element.get("file"), path.parent / folder / element.get("file")))
    return refs


def _sdf(kit: Kit, path: Path) -> list[tuple[str, Path | None]]:
    root = ET.parse(path).getroot()
    return [
        (uri.text or "", _uri(kit, path.parent, (uri.text or "").strip()))
        for uri in root.iter("uri")
    ]


def _usd(kit: Kit, path: Path) -> list[tuple[str, Path | None]]:
    from pxr import UsdUtils

    layers, assets, unresolved = UsdUtils.ComputeAllDependencies(str(path))
    refs = [(layer.realPath, Path(layer.realPath)) for layer in layers]
    refs += [(asset, Path(asset)) for asset in assets]
    return refs + [(missing, None) for missing in unresolved]


def _glb(kit: Kit, path: Path) -> list[tuple[str, Path | None]]:
    data = path.read_bytes()
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20 : 20 + length])
    uris = [
        item["uri"] for key in ("buffers", "images") for item in doc.get(key, []) if "uri" in item
    ]
    return [(uri, path.parent / uri) for uri in uris if not uri.startswith("data:")]


READERS = {
    ".urdf": "urdf",
    ".xml": "mjcf",
    ".sdf": "sdf",
    ".usda": "usd",
    ".usdc": "usd",
    ".usd": "usd",
    ".glb": "glb",
}


def check_references(kit: Kit) -> list[Finding]:
    """Every model's references inside the kit; copied blocks' external ones listed."""
    outside, external, counted = [], [], 0
    for path in sorted(kit.root.rglob("*")):
        kind = READERS.get(path.suffix)
        if kind is None or not path.is_file() or (kind == "mjcf" and path.parent.name != "mjcf"):
            continue
        rel = path.relative_to(kit.root).as_posix()
        try:
            if kind == "urdf":
                refs, found = _urdf(kit, path)
                external += [f"{rel}: {f}" for f in found]
            else:
                refs = {"mjcf": _mjcf, "sdf": _sdf, "usd": _usd, "glb": _glb}[kind](kit, path)
        except (ET.ParseError, ValueError, KeyError, struct.error, OSError) as exc:
            outside.append(f"{rel}: unreadable ({type(exc).__name__})")
            continue
        counted += len(refs)
        outside += [
            f"{rel}: {ref!r}" for ref, target in refs if target is None or not _inside(kit, target)
        ]
    detail = f"{counted} geometry and asset references, all inside the kit"
    if external:
        detail += f"; external references in copied blocks: {', '.join(sorted(set(external))[:5])}"
    if outside:
        detail = f"{len(outside)} reference(s) outside the kit: {'; '.join(outside[:3])}"
    return [require("references.inside", not outside, detail)]
