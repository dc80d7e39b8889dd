"""PNG bytes through Pillow, written the same way every time: RGB, 8 bits, no text or time
chunks, a fixed zlib level, so the same pixels give the same bytes (renders, thumbnails)."""

from __future__ import annotations

import io

import numpy as np

COMPRESS_LEVEL = 6


def png_bytes(pixels: np.ndarray) -> bytes:
    """An (H, W, 3) uint8 RGB array as PNG bytes."""
    from PIL import Image

    buf = io.BytesIO()
    image = Image.fromarray(np.ascontiguousarray(pixels, dtype=np.uint8), "RGB")
    image.save(buf, format="PNG", compress_level=COMPRESS_LEVEL)
    return buf.getvalue()
