"""Pictures for the report: PNG data URIs, zoomed crops and error heatmaps (Pillow, NumPy).

Everything is embedded in the HTML file, so PNGs are optimised and kept small.
"""

from __future__ import annotations

import base64

import numpy as np

from ..draw.png import png_bytes, to_pixels

#: A crop never shows less than this many pixels across, so a tiny quad keeps some context.
MIN_CROP = 16
#: Nor more than this: a large quad is zoomed at its centre, where the split moves the attribute most.
MAX_CROP = 96


def data_uri(png: bytes) -> str:
    """``data:image/png;base64,...`` for an ``<img src>``."""
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def image_uri(image: np.ndarray) -> str:
    """Data URI of a float RGB image (H, W, 3) in [0, 1]."""
    return data_uri(png_bytes(to_pixels(image)))


def crop_box(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    """A square window on the pixels of ``mask`` (H, W) bool: (top, bottom, left, right), or None if empty.

    The window is centred on the pixels' centroid and spans 1.3 times their
    larger extent, clamped to [MIN_CROP, MAX_CROP] and shifted to stay inside
    the image (it shrinks only when the image itself is smaller).
    """
    rows, cols = np.nonzero(mask)
    if len(rows) == 0:
        return None
    height, width = mask.shape
    extent = max(np.ptp(rows), np.ptp(cols)) + 1
    side = int(min(max(1.3 * extent, MIN_CROP), MAX_CROP, height, width))
    top = int(np.clip(round(rows.mean() - side / 2), 0, height - side))
    left = int(np.clip(round(cols.mean() - side / 2), 0, width - side))
    return top, top + side, left, left + side


def zoomed_uri(image: np.ndarray, box: tuple[int, int, int, int], size: int) -> str:
    """Data URI of ``image`` (H, W, 3) float cut to ``box`` and scaled to ``size`` pixels square.

    Nearest-neighbour scaling: the pixels stay visible as pixels, so a crease is
    not blurred away.
    """
    from PIL import Image

    top, bottom, left, right = box
    crop = Image.fromarray(to_pixels(image[top:bottom, left:right]))
    return data_uri(png_bytes(np.asarray(crop.resize((size, size), Image.Resampling.NEAREST))))


def heatmap_uri(error: np.ndarray, covered: np.ndarray, vmax: float) -> str:
    """Data URI of a per-pixel error (H, W) as a heatmap: white 0 to dark red ``vmax``; uncovered pixels light grey.

    One ``vmax`` for every heatmap of a mesh, so their colours compare.
    """
    t = np.clip(np.nan_to_num(error) / vmax, 0.0, 1.0)[..., None] if vmax > 0 else np.zeros(error.shape + (1,))
    # White -> orange -> dark red: a perceptually ordered ramp that prints well.
    stops = np.array([[1.0, 1.0, 1.0], [0.99, 0.55, 0.24], [0.50, 0.0, 0.05]])
    low = stops[0] + (stops[1] - stops[0]) * np.minimum(2 * t, 1.0)
    colour = np.where(t < 0.5, low, stops[1] + (stops[2] - stops[1]) * (2 * t - 1.0))
    colour[~covered] = (0.93, 0.93, 0.93)
    return image_uri(colour)
