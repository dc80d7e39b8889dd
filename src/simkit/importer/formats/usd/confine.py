"""The USD file is untrusted: every layer it composes is checked before the stage opens.

A stage resolves sublayers, references and payloads by asset path, and its resolver would
follow `../`, absolute paths and symlinks anywhere. So the layers are opened one by one
(`Sdf.Layer.FindOrOpen`, which reads that one file and composes nothing): each layer's
composition arcs (`GetCompositionAssetDependencies`: sublayers, references, payloads, in every
variant) are anchored to it and must resolve, symlinks followed, to a USD file inside the
model's folder (or a `--allow-read` folder) before that file is opened; value clips (layers
named in prim metadata) are refused. The stage is then opened over the layers already held
open, so it reads no other file. A refusal is one line naming the layer and the asset path.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from simkit.errors import SpecError

#: the suffixes of the layers a stage may compose (usdz packages are not read)
LAYER_SUFFIXES = (".usd", ".usda", ".usdc")
#: bytes of one layer and of all layers together; layers
MAX_LAYER = 256 * 1024 * 1024
MAX_TOTAL = 1024 * 1024 * 1024
MAX_LAYERS = 256


@dataclass
class Layers:
    """The layers a stage will compose, by resolved path (the root first), held open so the
    stage reuses them, and their bytes by path relative to the model's folder."""

    root: object = None
    held: list = field(default_factory=list)
    files: dict[str, bytes] = field(default_factory=dict)


def open_layers(path: Path, allowed: tuple[Path, ...]) -> Layers:
    """Every layer `path` composes, each checked before it is opened (module docstring);
    one-line SpecError on an asset path outside `allowed` or a layer that is not USD."""
    from pxr import Sdf

    folder = path.resolve().parent
    out = Layers()
    todo, seen, total = [path.resolve()], set(), 0
    while todo:
        file = todo.pop(0)
        if file in seen:
            continue
        seen.add(file)
        if len(seen) > MAX_LAYERS:
            raise SpecError(str(path), None, "layers", f"over {MAX_LAYERS} layers")
        data = file.read_bytes()
        total += len(data)
        if len(data) > MAX_LAYER or total > MAX_TOTAL:
            raise SpecError(str(file), None, "layer", "too large to read (over the size cap)")
        layer = _open(Sdf, file)
        out.held.append(layer)
        out.files[_relative(file, folder)] = data
        out.root = out.root or layer
        _no_clips(layer, file)
        for asset in sorted(set(layer.GetCompositionAssetDependencies())):
            todo.append(inside(file, asset, allowed))
    return out


def _open(Sdf, file: Path):
    """The one layer at `file`, parsed alone; one line when it is not a USD layer."""
    try:
        layer = Sdf.Layer.FindOrOpen(str(file))
    except Exception as exc:  # pxr raises Tf.ErrorException on a malformed layer
        why = " ".join(str(exc).split())[:160]
        raise SpecError(str(file), None, "layer", f"not a USD layer ({why})") from None
    if layer is None:
        raise SpecError(str(file), None, "layer", "not a USD layer")
    return layer


def inside(layer_file: Path, asset: str, allowed: tuple[Path, ...]) -> Path:
    """The file asset path `asset` (anchored to `layer_file`'s folder) names, symlinks
    followed; one line when it leaves every `allowed` folder, is not a USD layer file
    (suffix) or does not exist."""
    where = (str(layer_file), None, f"asset @{asset}@")
    if not asset or "://" in asset or asset.startswith("@"):
        raise SpecError(*where, "not a file path inside the model's folder: refused")
    target = (layer_file.parent / asset).resolve()
    if not any(target == a or a in target.parents for a in allowed):
        raise SpecError(*where, "resolves outside the model's folder: refused, nothing read")
    if target.suffix.lower() not in LAYER_SUFFIXES:
        raise SpecError(*where, f"not a USD layer ({target.suffix or 'no suffix'}): refused")
    if not target.is_file():
        raise SpecError(*where, "no such file")
    return target


def _no_clips(layer, file: Path) -> None:
    """Refuse value clips: their layers are named in prim metadata, not composition arcs."""
    found: list[str] = []

    def visit(path) -> None:
        spec = layer.GetObjectAtPath(path)
        prim = spec is not None and hasattr(spec, "GetInfo") and path.IsPrimPath()
        if prim and (spec.HasInfo("clips") or spec.HasInfo("clipAssetPaths")):
            found.append(str(path))

    layer.Traverse("/", visit)
    if found:
        raise SpecError(str(file), None, f"prim {found[0]}", "value clips are not read: refused")


def _relative(file: Path, folder: Path) -> str:
    """`file`'s path relative to the model's folder (posix), else its name (an allowed
    folder outside it)."""
    try:
        return file.relative_to(folder).as_posix()
    except ValueError:
        return file.name
