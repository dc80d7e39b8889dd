"""Kit zips deflate their members on threads (kitio/archive.py) and must still be the bytes
zipfile's sequential `writestr` at level 9 gives: the published zip's digest is recorded in
the manifest and compared by every no-op rebuild."""

from __future__ import annotations

import io
import zipfile

import numpy as np

from simkit.kitio.archive import FILE_MODE, FIXED_TIME, read_zip, zip_bytes


def _sequential(files: dict[str, bytes], top: str) -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for path in sorted(files):
            info = zipfile.ZipInfo(f"{top}/{path}", date_time=FIXED_TIME)
            info.external_attr = FILE_MODE << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3
            archive.writestr(info, files[path], compresslevel=9)
    return buffer.getvalue()


def test_threaded_deflate_gives_zipfile_s_bytes():
    rng = np.random.default_rng(0)
    files = {
        "meshes/visual/big.stl": rng.random(400_000).astype(np.float32).tobytes(),
        "robot.json": b'{"name": "x"}\n' * 5000,
        "empty.txt": b"",
        "urdf/x.urdf": b"<robot/>",
        "docs/caf\u00e9.md": "caf\u00e9\n".encode(),
    }
    data = zip_bytes(files, "x_description")
    assert data == _sequential(files, "x_description")
    assert read_zip(data) == files
