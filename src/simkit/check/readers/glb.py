"""A GLB (glTF 2.0 binary) reader, independent of the emitter: the JSON document and the BIN
chunk, as the glTF 2.0 specification ("GLB File Format Specification") lays them out."""

from __future__ import annotations

import json
import struct


def read_glb(data: bytes) -> tuple[dict, bytes]:
    """Split a GLB into its JSON document and BIN chunk (checks, diff, tests)."""
    magic, version, total = struct.unpack_from("<4sII", data, 0)
    if magic != b"glTF" or version != 2 or total != len(data):
        raise ValueError("not a glTF 2.0 binary")
    length, kind = struct.unpack_from("<I4s", data, 12)
    if kind != b"JSON":
        raise ValueError("first GLB chunk is not JSON")
    doc = json.loads(data[20 : 20 + length])
    offset = 20 + length
    binary = b""
    if offset < len(data):
        blen, bkind = struct.unpack_from("<I4s", data, offset)
        binary = data[offset + 8 : offset + 8 + blen] if bkind == b"BIN\0" else b""
    return doc, binary
