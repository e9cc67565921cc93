"""Texture filtering as a renderer does it at the base level, and a min/max pyramid for bounds.

Texture coordinates follow OpenGL: ``(0, 0)`` is the bottom-left of the image,
``v`` grows upward, texel centres sit at half-integers, and coordinates wrap
(repeat) outside [0, 1]. Texel coordinates (``x``, ``y``) are continuous with
texel ``i``'s centre at ``i``: ``x = u W - 1/2``, ``y = (1 - v) H - 1/2``.
"""

from __future__ import annotations

import numpy as np


def texel_coordinates(uv: np.ndarray, width: int, height: int) -> np.ndarray:
    """(..., 2) float64 texel coordinates (x, y) of uv (..., 2)."""
    uv = np.asarray(uv, dtype=np.float64)
    return np.stack([uv[..., 0] * width - 0.5, (1.0 - uv[..., 1]) * height - 0.5], axis=-1)


def _corners(width: int, height: int, uv: np.ndarray):
    """The four texels bilinear filtering reads at OpenGL uv (N, 2) with repeat wrapping, as flat indices
    (4, N) int64 (top-left, top-right, bottom-left, bottom-right), and the weights (N, 1) float32 of the
    right and bottom ones (:func:`texel_coordinates`' x, y, computed column by column)."""
    uv = np.asarray(uv, dtype=np.float64)
    x, y = uv[:, 0] * width - 0.5, (1.0 - uv[:, 1]) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0).astype(np.float32)[:, None], (y - y0).astype(np.float32)[:, None]
    x0, y0 = _wrapped_texels(x0, width), _wrapped_texels(y0, height)
    x1, y1 = _wrapped_texels(x0 + 1, width), _wrapped_texels(y0 + 1, height)
    row0, row1 = y0 * width, y1 * width
    index = np.empty((4, len(x0)), dtype=np.int64)
    for out, (row, column) in zip(index, ((row0, x0), (row0, x1), (row1, x0), (row1, x1))):
        np.add(row, column, out=out)
    return index, fx, fy


def _wrapped_texels(texel: np.ndarray, size: int) -> np.ndarray:
    """(N,) int64: integer texel indices ``texel`` (N,) (float or int) repeated into [0, size); a bit mask for
    a power-of-two size (the common case: no division per texel)."""
    if texel.dtype.kind == "f" and len(texel) and not (-2.0**62 < texel.min() and texel.max() < 2.0**62):
        texel = np.fmod(texel, size)  # beyond int64 (uv of 1e15 and up): fmod is exact, and keeps the texel
    texel = texel.astype(np.int64, copy=False)
    if size & (size - 1) == 0:
        return texel & (size - 1)
    return texel % size


def _blend(texels, fx: np.ndarray, fy: np.ndarray) -> np.ndarray:
    """Bilinear blend of the four texels (top-left, top-right, bottom-left, bottom-right), each (N, C) float32
    (overwritten), by the weights ``fx``, ``fy`` (N, 1): a + (b - a) f, left to right, then top to bottom."""
    top_left, top_right, bottom_left, bottom_right = texels
    top = np.subtract(top_right, top_left, out=top_right)
    top *= fx
    top += top_left
    bottom = np.subtract(bottom_right, bottom_left, out=bottom_right)
    bottom *= fx
    bottom += bottom_left
    bottom -= top
    bottom *= fy
    bottom += top
    return bottom


def sample_bilinear(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Bilinear texture filtering with repeat wrapping.

    Parameters
    ----------
    image : (H, W, C) float or uint8
    uv : (N, 2) float, OpenGL texture coordinates

    Returns
    -------
    (N, C) float32, in the image's own units (0-255 for uint8).
    """
    height, width, channels = image.shape
    flat = image.reshape(-1, channels)
    index, fx, fy = _corners(width, height, uv)
    return _blend([flat.take(i, axis=0).astype(np.float32) for i in index], fx, fy)


class PackedTexture:
    """A uint8 texture of at most four channels with each texel's channels in one uint32, so that bilinear
    filtering gathers one word per texel (the lint samples millions of points per texture).

    ``texels`` (H, W, D) uint8 holds the texture in its first ``channels`` (default D) channels; C-contiguous
    four-byte texels (as :func:`~affinity.textures.decode.decode` gives them) are used as they are, others are
    copied into them. ``sample(uv)`` equals :func:`sample_bilinear` of ``texels[..., :channels]``.
    """

    def __init__(self, texels: np.ndarray, channels: int | None = None):
        height, width, depth = texels.shape
        channels = depth if channels is None else channels
        if depth != 4 or not texels.flags.c_contiguous:
            padded = np.zeros((height, width, 4), dtype=np.uint8)
            padded[..., :channels] = texels[..., :channels]
            texels = padded
        self.shape = (height, width, channels)
        self.words = texels.view(np.uint32).reshape(-1)

    def sample(self, uv: np.ndarray) -> np.ndarray:
        """(N, C) float32 in 0-255: bilinear samples at OpenGL uv (N, 2), repeating."""
        height, width, channels = self.shape
        index, fx, fy = _corners(width, height, uv)
        words = self.words.take(np.stack(index))  # (4, N) uint32: one gather for the four texels
        # All four bytes converted and blended, the padding sliced off last: converting a contiguous
        # (4, N, 4) block is several times faster than a strided (4, N, C) slice of it.
        texels = words.view(np.uint8).reshape(4, -1, 4).astype(np.float32)
        return _blend(texels, fx, fy)[:, :channels]


#: Texel rows a band of a pyramid level covers (a band is at least one row of its level): a query reduces only
#: the bands its boxes reach.
BAND_TEXELS = 32


class RangePyramid:
    """Per-channel minimum and maximum over blocks of 2^k x 2^k texels, level k = 0, 1, ..., built lazily.

    A box of texels is covered by at most 2 x 2 blocks of the first level whose block is
    at least as wide as the box, so :meth:`channel_bounds` answers any box in four lookups.
    A level is reduced by bands of its rows (:data:`BAND_TEXELS` rows of level 0, or one row of
    a level whose blocks are taller), straight from the rows of level 0 they cover, when a query
    first reaches them: boxes over a small part of a texture reduce only that part, and a
    block's values do not depend on which bands were built (one pass over the image answers
    a box spanning it).

    Memory, allocated up front but touched only where bands are built: two pyramids of about
    1/3 of the image each above level 0 (uint8 like the image); with ``minima=False`` the maxima
    only (the minima :meth:`channel_bounds` gives are then 0); level 0 itself when it is
    computed by ``rows``.

    Parameters
    ----------
    image : (H, W, D) uint8 array, level 0; or None, with ``rows``, ``fold`` and ``shape``
    minima : keep the minima too (only of an ``image``)
    channels : the first ``channels`` of the D are the image's (default D); bounds are given for them
    rows : ``rows(start, stop)`` -> (stop - start, W, E) uint8, level 0's rows before ``fold``, computed
        when a band needs them
    fold : (..., E) -> (..., D), a maximum over groups of the E values (it commutes with the blocks' maxima,
        so a level is folded after its reduction: the cheaper order)
    shape : (H, W, D) of level 0 when it is given by ``rows``
    """

    def __init__(self, image: np.ndarray | None = None, minima: bool = True, channels: int | None = None, *,
                 rows=None, fold=None, shape: tuple[int, int, int] | None = None):
        if image is None and minima:
            raise ValueError("a pyramid of computed rows keeps maxima only")
        shape = image.shape if image is not None else tuple(shape)
        self.shape, self.minima = (*shape[:2], shape[2] if channels is None else channels), minima
        self._image, self._rows, self._fold = image, rows, fold
        sizes = [shape[:2]]
        while max(sizes[-1]) > 1:
            sizes.append(((sizes[-1][0] + 1) // 2, (sizes[-1][1] + 1) // 2))
        self._levels = [(np.empty((*size, shape[2]), dtype=np.uint8) if minima else None,
                         np.empty((*size, shape[2]), dtype=np.uint8)) for size in sizes[1:]]
        base = image if image is not None else np.empty(shape, dtype=np.uint8)
        self._levels.insert(0, (base if minima else None, base))  # a texel is its own minimum and maximum
        self._band_rows = [max(1, BAND_TEXELS >> k) for k in range(len(sizes))]
        self._built = [np.zeros(-(-size[0] // rows), dtype=bool) for size, rows in zip(sizes, self._band_rows)]
        self._built[0][:] = image is not None

    @property
    def levels(self) -> int:
        """The number of levels (the last one a single block)."""
        return len(self._levels)

    @property
    def built_bytes(self) -> int:
        """Bytes of the bands built so far (the memory the pyramid holds beyond its ``image``: its arrays are
        allocated up front, but their pages are touched only where bands are built)."""
        total = 0
        for k, ((low, high), built, band_rows) in enumerate(zip(self._levels, self._built, self._band_rows)):
            if k == 0 and self._image is not None:
                continue  # the image itself, not the pyramid's
            row_bytes = high[0].nbytes if len(high) else 0
            total += int(built.sum()) * band_rows * row_bytes * (1 if low is None or k == 0 else 2)
        return total

    def channel_bounds(self, x0: np.ndarray, x1: np.ndarray, y0: np.ndarray,
                       y1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N, C) float64 per-channel minimum and maximum over the texel boxes [x0, x1] x [y0, y1]
        (inclusive int64 texel indices, (N,) each, inside the image)."""
        channels = self.shape[2]
        extent = np.maximum(x1 - x0, y1 - y0) + 1
        level = np.minimum(np.ceil(np.log2(np.maximum(extent, 1))).astype(np.int64), self.levels - 1)
        lows, highs = np.empty((len(x0), channels)), np.empty((len(x0), channels))
        for k in np.flatnonzero(np.bincount(level)).tolist():  # one pass per pyramid level (at most ~14)
            rows = np.flatnonzero(level == k)
            bx0, bx1, by0, by1 = x0[rows] >> k, x1[rows] >> k, y0[rows] >> k, y1[rows] >> k
            reached = np.zeros(len(self._built[k]), dtype=bool)
            reached[by0 // self._band_rows[k]] = reached[by1 // self._band_rows[k]] = True
            self._build(k, np.flatnonzero(reached))
            low, high = self._levels[k]
            blocks = [(by, bx) for by in (by0, by1) for bx in (bx0, bx1)]
            lows[rows] = _combined(low, blocks, np.minimum)[:, :channels] if self.minima else 0
            highs[rows] = _combined(high, blocks, np.maximum)[:, :channels]
        return lows, highs

    def _build(self, k: int, bands: np.ndarray) -> None:
        """Reduce the bands ``bands`` (sorted int64) of level ``k`` not built yet, straight from the rows of
        level 0 they cover (a block reduction: no level in between is needed)."""
        bands = bands[~self._built[k][bands]]
        if not len(bands):
            return
        low, high = self._levels[k]
        block, band_rows = 1 << k, self._band_rows[k]
        # Runs of consecutive bands, each reduced at once: a few array operations, not one per band.
        for run in np.split(bands, np.flatnonzero(np.diff(bands) != 1) + 1):
            start, stop = int(run[0]) * band_rows, min((int(run[-1]) + 1) * band_rows, len(high))
            first, last = start * block, min(stop * block, self.shape[0])
            if self._image is not None:
                base = self._image[first:last]
                high[start:stop] = _block_reduced(base, block, np.maximum)
                if self.minima:
                    low[start:stop] = _block_reduced(base, block, np.minimum)
            else:
                high[start:stop] = self._fold(_block_reduced(self._rows(first, last), block, np.maximum))
        self._built[k][bands] = True


def _combined(level: np.ndarray, blocks: list[tuple[np.ndarray, np.ndarray]], reduce) -> np.ndarray:
    """(N, D): ``reduce`` (np.minimum or np.maximum) over the entries of ``level`` (h, w, D) at ``blocks``, a
    few (rows, columns) pairs of (N,) indices; four-byte entries are gathered as one word each."""
    if level.shape[2] == 4 and level.flags.c_contiguous:
        words = level.view(np.uint32)[..., 0]
        entries = (words[by, bx].view(np.uint8).reshape(-1, 4) for by, bx in blocks)
    else:
        entries = (level[by, bx] for by, bx in blocks)
    combined = next(entries).copy()
    for entry in entries:
        reduce(combined, entry, out=combined)
    return combined


def _block_reduced(image: np.ndarray, block: int, reduce) -> np.ndarray:
    """(ceil(h / block), ceil(W / block), D): ``reduce`` (np.minimum or np.maximum) over the block x block
    blocks of ``image`` (h, W, D), a last partial block reduced over the texels it has (edge padding repeats
    them). Rows first, on whole contiguous rows, then columns."""
    height, width, depth = image.shape
    tall, wide = -height % block, -width % block
    if tall or wide:
        image = np.pad(image, ((0, tall), (0, wide), (0, 0)), mode="edge")
    rows = _reduced_axis(image.reshape(-1, block, image.shape[1] * depth), reduce)  # (h', W' D)
    return _reduced_axis(rows.reshape(len(rows), -1, block, depth).swapaxes(1, 2), reduce)


def _reduced_axis(blocks: np.ndarray, reduce) -> np.ndarray:
    """``reduce`` over axis 1 of ``blocks`` (n, b, ...): elementwise over the b slices while b is small (a
    reduction over a short axis is slower), a reduction when it is long."""
    if blocks.shape[1] == 1:
        return blocks[:, 0]
    if blocks.shape[1] > 16:
        return reduce.reduce(blocks, axis=1)
    out = blocks[:, 0].copy()
    for j in range(1, blocks.shape[1]):
        reduce(out, blocks[:, j], out=out)
    return out
