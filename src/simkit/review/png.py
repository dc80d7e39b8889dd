"""PNG files of renders and diff pages: the bytes come from kitio/png.py (RGB, 8 bits, no
text or time chunks, a fixed zlib level), so the same pixels give the same bytes."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from simkit.kitio.png import COMPRESS_LEVEL, png_bytes

__all__ = ["COMPRESS_LEVEL", "png_bytes", "read_png", "write_png"]


def write_png(path: Path, pixels: np.ndarray) -> None:
    path.write_bytes(png_bytes(pixels))


def read_png(path: Path) -> np.ndarray:
    """A PNG file as an (H, W, 3) uint8 RGB array."""
    from PIL import Image

    with Image.open(path) as image:
        return np.asarray(image.convert("RGB"), dtype=np.uint8)
