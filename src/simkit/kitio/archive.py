"""Reproducible zips: sorted entries, fixed timestamp and permissions, one top folder."""

from __future__ import annotations

import io
import zipfile

FIXED_TIME = (1980, 1, 1, 0, 0, 0)
FILE_MODE = 0o100644


def zip_bytes(files: dict[str, bytes], top: str) -> bytes:
    """A zip of `files` (POSIX paths) under folder `top`, byte-identical for equal input."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for path in sorted(files):
            info = zipfile.ZipInfo(f"{top}/{path}", date_time=FIXED_TIME)
            info.external_attr = FILE_MODE << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3
            archive.writestr(info, files[path], compresslevel=9)
    return buffer.getvalue()


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
