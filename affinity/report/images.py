"""Pictures for the report: PNG data URIs, error heatmaps and their colour bars (Pillow, NumPy).

Everything is embedded in the HTML file, so PNGs are optimised and kept small;
colour bars are inline SVG, so their labels are text at the page's own size.
"""

from __future__ import annotations

import base64
from html import escape

import numpy as np

from ..draw import png_bytes, to_pixels

#: The heatmaps' ramp, white (no error) -> orange -> dark red (the scale's top): ordered, and prints well.
HEAT_STOPS = ((1.0, 1.0, 1.0), (0.99, 0.55, 0.24), (0.50, 0.0, 0.05))
UNCOVERED = (0.93, 0.93, 0.93)


def data_uri(png: bytes) -> str:
    """``data:image/png;base64,...`` for an ``<img src>``."""
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def image_uri(image: np.ndarray) -> str:
    """Data URI of a float RGB image (H, W, 3) in [0, 1]."""
    return data_uri(png_bytes(to_pixels(image)))


def heatmap_uri(error: np.ndarray, covered: np.ndarray, vmax: float) -> str:
    """Data URI of a per-pixel error (H, W) as a heatmap: white 0 to dark red at ``vmax`` and beyond; pixels not
    ``covered`` (H, W) bool light grey."""
    t = np.clip(np.nan_to_num(error) / vmax, 0.0, 1.0)[..., None] if vmax > 0 else np.zeros(error.shape + (1,))
    stops = np.array(HEAT_STOPS)
    low = stops[0] + (stops[1] - stops[0]) * np.minimum(2 * t, 1.0)
    colour = np.where(t < 0.5, low, stops[1] + (stops[2] - stops[1]) * (2 * t - 1.0))
    colour[~covered] = UNCOVERED
    return image_uri(colour)


def _hex(rgb) -> str:
    return "#" + "".join(f"{round(c * 255):02x}" for c in rgb)


def colour_bar(stops, ticks: list[tuple[float, str]], label: str, width: int = 240) -> str:
    """An inline SVG colour bar: the ramp through ``stops`` (RGB in [0, 1], evenly spaced), tick labels, a unit label.

    ``ticks`` are (position in [0, 1] along the bar, text); ``label`` names the
    quantity and its unit. The bar is ``width`` pixels wide at most: its shapes are
    placed in percent of its width, so a narrower box shrinks the ramp and keeps the
    text at 12 px, legible wherever the bar is.
    """
    gradient = "".join(f'<stop offset="{k / (len(stops) - 1):.3f}" stop-color="{_hex(c)}"/>'
                       for k, c in enumerate(stops))
    bar_id = f"bar{abs(hash((tuple(map(tuple, stops)), label))) % 10**8}"
    margin = 100 * 8 / width  # percent

    def along(t: float) -> str:
        return f"{margin + t * (100 - 2 * margin):.2f}%"

    marks = "".join(
        f'<line x1="{along(t)}" x2="{along(t)}" y1="20" y2="25" stroke="#374151"/>'
        f'<text x="{along(t)}" y="38" text-anchor="{"start" if t == 0 else "end" if t == 1 else "middle"}">'
        f'{escape(text)}</text>' for t, text in ticks)
    return (f'<svg class="colour-bar" role="img" aria-label="colour bar: {escape(label)}" width="{width}" height="58" '
            f'font-size="12" fill="#1f2937" font-family="system-ui, sans-serif">'
            f'<defs><linearGradient id="{bar_id}">{gradient}</linearGradient></defs>'
            f'<rect x="{along(0)}" y="6" width="{100 - 2 * margin:.2f}%" height="14" fill="url(#{bar_id})" '
            f'stroke="#9ca3af"/>{marks}<text x="50%" y="54" text-anchor="middle">{escape(label)}</text></svg>')


def heat_bar(vmax: float, label: str) -> str:
    """The colour bar of :func:`heatmap_uri` at scale ``vmax``, labelled ``label`` (quantity and unit)."""
    return colour_bar(HEAT_STOPS, [(0.0, "0"), (0.5, f"{vmax / 2:.3g}"), (1.0, f"≥ {vmax:.3g}")], label)
