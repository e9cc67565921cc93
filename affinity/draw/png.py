"""Float images to PNG (Pillow, imported when used): in memory for the report, or as files."""

from __future__ import annotations

import io
import os

import numpy as np


def to_pixels(image: np.ndarray) -> np.ndarray:
    """(H, W, C) float in [0, 1] -> (H, W, C) uint8."""
    return np.round(np.clip(image, 0.0, 1.0) * 255.0).astype(np.uint8)


def png_bytes(pixels: np.ndarray) -> bytes:
    """An optimised PNG of (H, W, 3) or (H, W) uint8 pixels."""
    from PIL import Image

    out = io.BytesIO()
    Image.fromarray(pixels).save(out, format="PNG", optimize=True)
    return out.getvalue()


def write_png(path: str | os.PathLike, pixels: np.ndarray) -> None:
    """Write (H, W, 3) uint8 pixels as a PNG file, atomically (raises OSError)."""
    from ..atomic import atomic_write

    with atomic_write(path, binary=True) as out:
        out.write(png_bytes(pixels))
