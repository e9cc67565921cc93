"""Textures for renders: a procedural checker, image files, and the close-ups' line pattern.

Image files are decoded, and sampled bilinearly, by the core (:mod:`affinity.textures`).

Texture coordinates follow OpenGL: ``(0, 0)`` is the bottom-left of the image,
``v`` grows upward, and coordinates wrap (repeat) outside [0, 1].
"""

from __future__ import annotations

import functools
import weakref

import numpy as np

from ..textures.filtering import sample_bilinear

__all__ = ["TextureError", "checker", "load_image", "sample_bilinear", "sample_mipmapped"]

CHECKS = 32


def painted_texture(mesh) -> str | None:
    """The image file a render paints the whole mesh with, the renderer taking one texture: the ``map_Kd``
    of the first material that has one, or None. Only renders paint one image; everything that measures
    reads each face's own maps (:mod:`affinity.textures.binding`)."""
    for name in mesh.material_names:
        if name in mesh.material_textures:
            return mesh.material_textures[name]
    return next(iter(mesh.material_textures.values()), None)


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


def mip_levels(image: np.ndarray) -> list[np.ndarray]:
    """The mip pyramid of ``image`` (H, W, C): level 0 the image as float32, each next level the mean of 2 x 2
    texels of the one before (an odd last row or column averaged with the row or column before), down to 1 x 1.
    """
    levels = [np.asarray(image, dtype=np.float32)]
    while max(levels[-1].shape[:2]) > 1:
        level = levels[-1]
        if level.shape[0] % 2 and level.shape[0] > 1:
            level = np.concatenate([level[:-2], (level[-2:-1] + level[-1:]) / 2], axis=0)
        if level.shape[1] % 2 and level.shape[1] > 1:
            level = np.concatenate([level[:, :-2], (level[:, -2:-1] + level[:, -1:]) / 2], axis=1)
        rows, columns = max(level.shape[0] // 2, 1), max(level.shape[1] // 2, 1)
        level = level.reshape(rows, level.shape[0] // rows, columns, level.shape[1] // columns, -1).mean(axis=(1, 3))
        levels.append(level.astype(np.float32))
    return levels


#: Added to every pixel's level of detail: at 0 a pattern of 2-texel cells meets 1-texel pixels at its Nyquist
#: limit and still beats into moire (the car's per-face checker); half a level more averages those cells out.
LOD_BIAS = 0.5


#: Pyramids of read-only textures (the cached checker, say), by id, with a weak reference that proves the id's
#: array is still the one the pyramid was built from: building one costs a 1024-texel checker 0.17 s.
_PYRAMIDS: dict[int, tuple] = {}


def _pyramid(image: np.ndarray) -> list[np.ndarray]:
    """:func:`mip_levels` of ``image``, built once for a read-only array, every time for a writeable one."""
    if image.flags.writeable:
        return mip_levels(image)
    known = _PYRAMIDS.get(id(image))
    if known is None or known[0]() is not image:
        if len(_PYRAMIDS) >= 4:
            _PYRAMIDS.clear()
        known = _PYRAMIDS[id(image)] = (weakref.ref(image), mip_levels(image))
    return known[1]


def sample_mipmapped(image: np.ndarray, uv: np.ndarray, footprint: np.ndarray) -> np.ndarray:
    """Trilinear texture filtering: bilinear in the two mip levels around each pixel's level of detail, blended.

    The level of detail is ``log2`` of the pixel's footprint in texels, the larger of ``footprint`` (N, 2) (the
    change of u and v from the pixel to its neighbours) times the texture's width and height (OpenGL's isotropic
    rule, spec 4.6 eq. 8.7 with the larger axis), plus ``LOD_BIAS``; a footprint under 2^-LOD_BIAS texels, or
    NaN, reads level 0, so a magnified texture is filtered exactly as :func:`sample_bilinear` does. Where
    texels are smaller than a pixel the pattern's mean replaces what base-level sampling would alias into moire.

    Parameters
    ----------
    image : (H, W, C) float
    uv : (N, 2) float, OpenGL texture coordinates
    footprint : (N, 2) float, NaN where unknown

    Returns
    -------
    (N, C) float32
    """
    height, width = image.shape[:2]
    texels = np.nan_to_num(np.asarray(footprint, dtype=np.float64) * [width, height], nan=0.0).max(axis=1)
    with np.errstate(divide="ignore"):
        detail = np.maximum(np.log2(texels) + LOD_BIAS, 0.0)
    if not (detail > 0).any():
        return sample_bilinear(image, uv)
    levels = _pyramid(image)
    detail = np.minimum(detail, len(levels) - 1)
    below = np.floor(detail).astype(np.int64)
    blend = (detail - below).astype(np.float32)[:, None]
    out = np.empty((len(uv), image.shape[2]), dtype=np.float32)
    for level in np.unique(below):  # one pass per mip level, not per pixel
        rows = np.flatnonzero(below == level)
        lower = sample_bilinear(levels[level], uv[rows])
        upper = sample_bilinear(levels[min(level + 1, len(levels) - 1)], uv[rows])
        out[rows] = lower + blend[rows] * (upper - lower)
    return out


class TextureError(Exception):
    """A texture file that cannot be used."""


def load_image(path: str) -> np.ndarray:
    """Read an image file as (H, W, 3) float32 RGB in [0, 1], read-only: decoded by the core
    (:func:`affinity.textures.decode.decode`: once per run, never over the pixel budget), and kept for the
    file's size and modification time, so the renders of one report share it and its mip pyramid.

    Raises :class:`TextureError` naming the file and why it is not used."""
    import os

    try:
        status = os.stat(path)
        stamp = (status.st_mtime_ns, status.st_size)
    except OSError:
        stamp = None
    return _load_rgb(os.fspath(path), stamp)


@functools.lru_cache(maxsize=4)
def _load_rgb(path: str, stamp: tuple | None) -> np.ndarray:
    """:func:`load_image` of ``path`` as it was at ``stamp`` (modification time and size)."""
    from ..loaders.regular import NOT_READ
    from ..textures.decode import TextureUnusable, decode

    try:
        pixels = decode(path).pixels
    except TextureUnusable as err:
        reason = str(err)
        if reason == "missing":
            reason = "no such texture file"
        elif not reason.endswith(NOT_READ):  # a FIFO or a device says what it is; anything else is no image
            reason = f"not a readable image ({reason})"
        raise TextureError(f"{path}: {reason}") from None
    grey_or_colour = pixels[..., :3] if pixels.shape[2] >= 3 else np.repeat(pixels[..., :1], 3, axis=2)
    image = grey_or_colour.astype(np.float32) / 255.0
    image.flags.writeable = False
    return image


#: Lines of the close-up pattern are this many pixels apart on screen, and this many pixels wide.
LINE_SPACING = 6.0
LINE_WIDTH = 1.5
PAPER = np.array([0.96, 0.94, 0.88])
U_INK = np.array([0.12, 0.28, 0.62])
V_INK = np.array([0.80, 0.18, 0.12])


def pixel_footprint(uv: np.ndarray, where: np.ndarray | None = None) -> float:
    """The median uv distance between neighbouring pixels of a frame's uv (H, W, 2) float (NaN where empty),
    over the pixels ``where`` (H, W) bool (default: all; all as well when ``where`` has none to measure).

    The scale at which a close-up's pattern is drawn: lines ``LINE_SPACING`` pixels
    apart are ``LINE_SPACING`` footprints apart in uv. 1.0 when no two neighbours are covered.
    """
    steps = np.linalg.norm(local_footprints(uv), axis=-1)
    measured = np.isfinite(steps) & (steps > 0)
    if where is not None and (measured & where).any():
        measured &= where
    return float(np.median(steps[measured])) if measured.any() else 1.0


def glyph_footprints(uv: np.ndarray, where: np.ndarray, footprint: float) -> np.ndarray:
    """(2,) float64: the median change of u and of v between neighbouring pixels of a frame's uv (H, W, 2) over
    the pixels ``where`` (H, W) bool, each ``footprint`` where it cannot be measured: a glyph cell of
    ``GLYPH_SPACING`` of these is square on screen however differently u and v are scaled."""
    steps = local_footprints(uv)[where]
    measured = np.isfinite(steps) & (steps > 0)
    return np.array([float(np.median(steps[measured[:, k], k])) if measured[:, k].any() else footprint
                     for k in range(2)])


def local_footprints(uv: np.ndarray) -> np.ndarray:
    """(H, W, 2) float64: how much u and v each change from a pixel to its neighbours (per coordinate, the
    larger of its row and column steps, each the smaller of the two sides, so a seam on one side does not
    count); NaN where no neighbour is covered."""
    def axis_step(axis: int) -> np.ndarray:
        step = np.abs(np.diff(uv, axis=axis))
        shape = list(step.shape)
        shape[axis] = 1
        pad = np.full(shape, np.nan)
        before, after = np.concatenate([pad, step], axis=axis), np.concatenate([step, pad], axis=axis)
        return np.fmin(before, after)

    return np.fmax(axis_step(0), axis_step(1))


#: The glyph pattern: a bold "F" (no mirror image of it is itself) in cells this many pixels wide and high on the
#: place (a few per quad of a close-up, big enough to read at page size), shown in full where a cell spans at
#: least ``GLYPH_FULL`` pixels, faded out below ``GLYPH_GONE``. Under glyphs the lines are drawn at
#: ``LINES_UNDER_GLYPHS`` of their ink, so the letter, not the grid, is what the eye reads.
GLYPH_SPACING = 8 * LINE_SPACING
GLYPH_FULL, GLYPH_GONE = 16.0, 10.0
LINES_UNDER_GLYPHS = 0.4
GLYPH_INK = np.array([0.10, 0.10, 0.12])
#: The F's strokes as (u0, u1, v0, v1) in a cell's unit square, v up: the stem, the top bar, the middle bar.
GLYPH_STROKES = np.array([[0.24, 0.42, 0.12, 0.88], [0.24, 0.80, 0.70, 0.88], [0.24, 0.66, 0.42, 0.57]])


def glyph_ink(uv: np.ndarray, footprint: float | np.ndarray, local: np.ndarray) -> np.ndarray:
    """(N,) float64 in [0, 1]: the ink of an upright "F" in every cell ``GLYPH_SPACING`` footprints square
    (``footprint`` a scalar, or (2,) per coordinate, so a cell is square on screen where u and v scale apart).

    Mirrored texture coordinates (u to -u, or v to -v) draw the F mirrored, so a close-up of a mirrored
    island shows it, as a checker or lines cannot. Each stroke is a rectangle in the cell's unit square;
    a pixel's ink is its box-filtered coverage, ``clip(1/2 + d, 0, 1)`` per axis at a signed distance ``d``
    pixels inside the stroke's edges (in the pixel's own footprint ``local`` (N, 2)), the strokes' union
    their maximum; the glyph fades out where a cell is under ``GLYPH_FULL`` pixels.
    """
    spacing = GLYPH_SPACING * footprint
    cell_pixels = spacing / np.maximum(local, 1e-300)  # (N, 2)
    cell = np.mod(np.asarray(uv, dtype=np.float64) / spacing, 1.0)  # (N, 2) position in the cell
    inside_u = np.minimum(cell[:, :1] - GLYPH_STROKES[:, 0], GLYPH_STROKES[:, 1] - cell[:, :1]) * cell_pixels[:, :1]
    inside_v = np.minimum(cell[:, 1:] - GLYPH_STROKES[:, 2], GLYPH_STROKES[:, 3] - cell[:, 1:]) * cell_pixels[:, 1:]
    ink = (np.clip(0.5 + inside_u, 0.0, 1.0) * np.clip(0.5 + inside_v, 0.0, 1.0)).max(axis=1)
    size = cell_pixels.min(axis=1)
    return ink * np.clip((size - GLYPH_GONE) / (GLYPH_FULL - GLYPH_GONE), 0.0, 1.0)


def line_colours(uv: np.ndarray, footprint: float, local: np.ndarray | None = None,
                 glyphs: np.ndarray | None = None) -> np.ndarray:
    """Antialiased lines of constant u (blue) and constant v (red), ``LINE_SPACING`` footprints apart.

    Computed from each pixel's coordinates: a pixel's ink is its coverage by a line
    ``LINE_WIDTH`` pixels wide (a box filter: ``clip(w / 2 + 1 / 2 - d, 0, 1)`` at a
    distance of ``d`` pixels from the line's centre), distances measured in the pixel's
    own footprint in that coordinate (``local``), so lines stay thin and smooth on near
    and far faces alike. Where a family's lines come closer than ``3 * LINE_WIDTH``
    pixels they fade to the pattern's mean ink (``LINE_WIDTH / LINE_SPACING``) instead
    of aliasing. Both families cross the split's diagonal, so where the split
    moves the texture they kink at it and the split and exact panels differ.

    Parameters
    ----------
    uv : (N, 2) float, texture coordinates
    footprint : the uv distance between neighbouring pixels that sets the spacing (:func:`pixel_footprint`)
    local : (N, 2) float, each pixel's own footprint in u and v (:func:`local_footprints`); None or NaN:
        ``footprint``
    glyphs : (2,) float, the footprint per coordinate of :func:`glyph_ink`'s "F" glyphs, drawn over lines
        lightened to ``LINES_UNDER_GLYPHS`` (a close-up of mirroring); None: lines only

    Returns
    -------
    (N, 3) float32 RGB.
    """
    spacing = LINE_SPACING * footprint
    local = np.full((len(uv), 2), footprint) if local is None else np.where(np.isfinite(local), local, footprint)
    apart = spacing / np.maximum(local, 1e-300)  # (N, 2) each family's spacing in this pixel's pixels
    scaled = np.asarray(uv, dtype=np.float64) / spacing
    distance = np.abs(scaled - np.round(scaled)) * apart  # pixels from the nearest line of each family
    ink = np.clip(LINE_WIDTH / 2 + 0.5 - distance, 0.0, 1.0)
    fade = np.clip(apart / LINE_WIDTH - 2.0, 0.0, 1.0)  # 0 where lines are 2 widths apart or closer
    ink = fade * ink + (1 - fade) * (LINE_WIDTH / LINE_SPACING)
    if glyphs is not None:
        ink *= LINES_UNDER_GLYPHS
    colour = PAPER + ink[:, :1] * (U_INK - PAPER)
    colour += ink[:, 1:] * (V_INK - colour)
    if glyphs is not None:
        colour += glyph_ink(uv, glyphs, local)[:, None] * (GLYPH_INK - colour)
    return colour.astype(np.float32)
