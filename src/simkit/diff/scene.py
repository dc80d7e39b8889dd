"""`simkit diff` for the GLB and USD scenes: equal but for round-off and their mesh arrays.

GLB and USD files carry the same meshes as the STLs (the checks compare them), so their
mesh arrays are compared through the STLs (`mesh`); everything else, node transforms
included, must agree within the tolerance. Node transforms are not reported as rows: they
follow the joint origins, which robot.json rows report.
"""

from __future__ import annotations

import re

from simkit.diff.tolerance import PARAM_SI, same, text_close

#: UsdGeomMesh attributes that hold the mesh itself (compared through the STLs)
USD_MESH_ARRAYS = re.compile(
    rb"((?:points|faceVertexIndices|faceVertexCounts|normals|extent|primvars:\w+)"
    rb"(?:\.\w+)?) = \[[^\]]*\]"
)


def usd_close(path: str, old: bytes, new: bytes) -> bool:
    """USD files equal but for round-off and their mesh arrays (text or crate)."""
    if path.endswith(".usdc") or old.startswith(b"PXR-USDC") or new.startswith(b"PXR-USDC"):
        old, new = _usd_text(path, old), _usd_text(path, new)
        if old is None or new is None:
            return False
    return text_close(USD_MESH_ARRAYS.sub(rb"\1 = []", old), USD_MESH_ARRAYS.sub(rb"\1 = []", new))


def _usd_text(path: str, data: bytes) -> bytes | None:
    """A USD crate as USDA text (pxr, lazily), or None where it cannot be read."""
    import tempfile
    from pathlib import Path

    try:
        from pxr import Sdf

        with tempfile.TemporaryDirectory(prefix="simkit-diff-") as tmp:
            file = Path(tmp) / Path(path).name
            file.write_bytes(data)
            layer = Sdf.Layer.FindOrOpen(str(file))
            text = layer.ExportToString() if layer else None
    except Exception:  # pxr raises its own error types on a damaged crate
        return None
    return text.encode("utf-8") if text is not None else None


def glb_close(old: bytes, new: bytes) -> bool:
    """GLB files equal but for round-off and their mesh data (accessor counts and bounds,
    buffer sizes and the BIN chunk); node transforms, materials and names must agree."""
    from simkit.check.readers.glb import read_glb

    try:
        docs = [read_glb(old)[0], read_glb(new)[0]]
    except (ValueError, IndexError, UnicodeDecodeError):
        return False
    for doc in docs:
        for accessor in doc.get("accessors", []):
            for key in ("count", "min", "max"):
                accessor.pop(key, None)
        for view in doc.get("bufferViews", []):
            view.pop("byteOffset", None)
            view.pop("byteLength", None)
        for buffer in doc.get("buffers", []):
            buffer.pop("byteLength", None)
    return same(docs[0], docs[1], PARAM_SI)
