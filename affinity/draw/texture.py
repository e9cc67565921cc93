"""Textures for renders: a procedural checker, image files, and bilinear sampling.

Texture coordinates follow OpenGL: ``(0, 0)`` is the bottom-left of the image,
``v`` grows upward, and coordinates wrap (repeat) outside [0, 1].
"""

from __future__ import annotations

import functools

import numpy as np

CHECKS = 32


@functools.lru_cache(maxsize=4)
def checker(size: int = 1024, checks: int = CHECKS) -> np.ndarray:
    """A checker with thin grid lines, so a bent diagonal stands out.

    Returns
    -------
    (size, size, 3) float32 RGB in [0, 1], read-only (cached: every render shares it).
    """
    cells = (np.arange(size) * checks) // size
    parity = (cells[:, None] + cells[None, :]) % 2
    light, dark = np.array([0.93, 0.90, 0.82]), np.array([0.22, 0.36, 0.55])
    image = np.where(parity[..., None] == 0, light, dark)
    period = size // checks
    line = (np.arange(size) % period) < max(1, period // 16)
    image[line, :] = image[:, line] = (0.85, 0.25, 0.15)
    image = image.astype(np.float32)
    image.flags.writeable = False
    return image


class TextureError(Exception):
    """A texture file that cannot be used."""


def load_image(path: str) -> np.ndarray:
    """Read an image file as (H, W, 3) float32 RGB in [0, 1] (Pillow, imported here)."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as image:
            return np.asarray(image.convert("RGB"), dtype=np.float32) / 255.0
    except FileNotFoundError:
        raise TextureError(f"{path}: no such texture file") from None
    except (UnidentifiedImageError, OSError) as err:
        raise TextureError(f"{path}: not a readable image ({err.__class__.__name__})") from None


def sample_bilinear(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Bilinear texture filtering with repeat wrapping.

    Parameters
    ----------
    image : (H, W, C) float
    uv : (N, 2) float, OpenGL texture coordinates

    Returns
    -------
    (N, C) float32
    """
    height, width = image.shape[:2]
    x = uv[:, 0] * width - 0.5
    y = (1.0 - uv[:, 1]) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[:, None], (y - y0)[:, None]
    x0 = x0.astype(np.int64) % width
    y0 = y0.astype(np.int64) % height
    x1, y1 = (x0 + 1) % width, (y0 + 1) % height
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bottom = image[y1, x0] * (1 - fx) + image[y1, x1] * fx
    return (top * (1 - fy) + bottom * fy).astype(np.float32)


#: Cells of the close-up grid across the largest uv extent of the quad it is about.
GRID_CELLS = 8


def grid_cell(uv: np.ndarray, cells: int = GRID_CELLS) -> float:
    """The grid cell (uv units) that puts ``cells`` cells across a quad's largest uv extent.

    ``uv`` (4, 2) float64: the quad's corner texture coordinates. A quad with no
    uv extent gets cells of 1/``cells``.
    """
    extent = float(np.ptp(uv, axis=0).max())
    return (extent if extent > 0 else 1.0) / cells


def grid_colours(uv: np.ndarray, cell: float) -> np.ndarray:
    """A procedural UV grid, a checker of ``cell``-sized squares with lines on the cell edges.

    Computed from the coordinates themselves rather than sampled from an image, so
    it stays sharp at any scale: a close-up on a quad a thousandth of the atlas
    wide still shows eight cells across it, and a bent diagonal bends the lines.

    Parameters
    ----------
    uv : (N, 2) float, texture coordinates
    cell : the side of one square, in uv units

    Returns
    -------
    (N, 3) float32 RGB: the checker's two colours, grid lines (1/12 of a cell wide) in red.
    """
    scaled = np.asarray(uv, dtype=np.float64) / cell
    whole = np.floor(scaled)
    parity = (whole[:, 0] + whole[:, 1]) % 2
    light, dark, line = np.array([0.93, 0.90, 0.82]), np.array([0.22, 0.36, 0.55]), np.array([0.85, 0.25, 0.15])
    colour = np.where(parity[:, None] == 0, light, dark)
    fraction = scaled - whole
    near_edge = (np.minimum(fraction, 1.0 - fraction) < 1.0 / 24).any(axis=1)
    colour[near_edge] = line
    return colour.astype(np.float32)
