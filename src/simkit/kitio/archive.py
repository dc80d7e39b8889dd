"""Reproducible zips: sorted entries, fixed timestamp and permissions, one top folder."""

from __future__ import annotations

import io
import os
import zipfile
import zlib
from concurrent.futures import ThreadPoolExecutor

FIXED_TIME = (1980, 1, 1, 0, 0, 0)
FILE_MODE = 0o100644


def zip_bytes(files: dict[str, bytes], top: str) -> bytes:
    """A zip of `files` (POSIX paths) under folder `top`, byte-identical for equal input.
    Each member is deflated at level 9 on its own thread (zlib releases the GIL: a robot's
    CAD meshes took seconds on one core); the streams are the ones zipfile's `writestr`
    makes (one `compress` call, then `flush`), so the bytes are too."""
    names = sorted(files)
    with ThreadPoolExecutor(max_workers=min(4, os.cpu_count() or 1)) as pool:
        streams = dict(zip(names, pool.map(lambda name: _deflate(files[name]), names), strict=True))
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for path in names:
            info = zipfile.ZipInfo(f"{top}/{path}", date_time=FIXED_TIME)
            info.external_attr = FILE_MODE << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3
            _write(archive, info, files[path], streams[path])
    return buffer.getvalue()


def _deflate(data: bytes) -> bytes:
    """The raw deflate stream zipfile writes for `data` at level 9."""
    compressor = zlib.compressobj(9, zlib.DEFLATED, -15)
    return compressor.compress(data) + compressor.flush()


class _Deflated:
    """A compressor that hands over a stream deflated beforehand."""

    def __init__(self, stream: bytes) -> None:
        self.stream = stream

    def compress(self, _data: bytes) -> bytes:
        out, self.stream = self.stream, b""
        return out

    def flush(self) -> bytes:
        return b""


def _write(archive: zipfile.ZipFile, info: zipfile.ZipInfo, data: bytes, stream: bytes) -> None:
    """`archive.writestr(info, data, compresslevel=9)` with the deflating done already: the
    member's writer takes the finished stream (its CRC and sizes are its own); a zipfile
    without that writer attribute deflates again itself."""
    info.file_size = len(data)  # as writestr sets it, before the header is written
    with archive.open(info, mode="w") as dest:
        if hasattr(dest, "_compressor"):
            dest._compressor = _Deflated(stream)
        else:  # pragma: no cover - another zipfile: its own compressor, level 9
            dest._compresslevel = 9
        dest.write(data)


def read_zip(data: bytes) -> dict[str, bytes]:
    """Files of a kit zip, keyed by path inside the kit: the top folder (the kit folder, as
    `zip_bytes` writes it) is dropped when every entry shares one; a zip of the kit's
    contents without a top folder is read as it is."""
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        files = {i.filename: archive.read(i) for i in archive.infolist() if not i.is_dir()}
    tops = {name.partition("/")[0] if "/" in name else None for name in files}
    if len(tops) == 1 and None not in tops:
        return {name.partition("/")[2]: data for name, data in files.items()}
    return files
