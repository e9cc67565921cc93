"""Decode a texture once per run, within a pixel budget checked against its header first.

A texture whose header claims more than :data:`DECODE_BUDGET` pixels is never
decoded (a 100,000 x 100,000 PNG header would ask for 30 GB); decoded textures
are kept as (H, W, C) uint8, at most :data:`CACHE_BYTES` of them at a time
(least recently used dropped first), keyed by path, size and modification time,
so each texture is decoded once per run however many meshes or rules read it.
Peak memory for textures: :data:`CACHE_BYTES` plus one texture being decoded
(at most ``DECODE_BUDGET x 4`` bytes) and its min/max pyramid (2/3 of it).
"""

from __future__ import annotations

import os
import threading
from collections import OrderedDict
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..loaders.imagesize import ImageHeader, ImageUnreadable, open_image_file, read_header

#: Pixels (width x height) a texture may have to be decoded: 8192 x 8192.
DECODE_BUDGET = 1 << 26
#: Decoded texture bytes kept between meshes of one run.
CACHE_BYTES = 1 << 29
#: Formats Pillow decodes; an EXR's size comes from its header, its texels are not read.


class TextureUnusable(Exception):
    """A texture that is not decoded; the message is the reason, for a note, and ``header`` what its
    header says (None when it cannot be read)."""

    def __init__(self, reason: str, header: ImageHeader | None = None):
        super().__init__(reason)
        self.header = header


@dataclass(frozen=True, eq=False)
class DecodedTexture:
    """A decoded texture.

    Attributes
    ----------
    path : the file
    header : what its header says (format and size)
    pixels : (H, W, C) uint8, read-only; C is 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA); row 0 the top
    """

    path: str
    header: ImageHeader
    pixels: np.ndarray

    @cached_property
    def pyramid(self):
        """The texture's min/max pyramid (:class:`~affinity.textures.filtering.RangePyramid`), built once."""
        from .filtering import RangePyramid

        return RangePyramid(self.pixels)

    @cached_property
    def slopes(self):
        """The pyramid of the texture's steps (:class:`~affinity.textures.filtering.RangePyramid` of (H, W, 2)
        uint8): the largest channel difference from each texel to the next column and to the next row,
        wrapping; bilinear filtering changes by at most their sum per texel moved."""
        from .filtering import RangePyramid

        pixels = self.pixels
        steps = np.empty((*pixels.shape[:2], 2), dtype=np.uint8)

        def largest_step(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
            step = np.maximum(a, b)
            step -= np.minimum(a, b)  # |a - b| in uint8
            largest = step[..., 0].copy()
            for channel in range(1, step.shape[2]):  # elementwise: faster than a reduction over a short axis
                np.maximum(largest, step[..., channel], out=largest)
            out[...] = largest

        largest_step(pixels[:, :-1], pixels[:, 1:], steps[:, :-1, 0])
        largest_step(pixels[:, -1:], pixels[:, :1], steps[:, -1:, 0])  # the last column wraps to the first
        largest_step(pixels[:-1], pixels[1:], steps[:-1, :, 1])
        largest_step(pixels[-1:], pixels[:1], steps[-1:, :, 1])
        return RangePyramid(steps, minima=False)

    @cached_property
    def packed(self):
        """The texels packed for sampling (:class:`~affinity.textures.filtering.PackedTexture`), built once."""
        from .filtering import PackedTexture

        return PackedTexture(self.pixels)

    @cached_property
    def looks_like_normal_map(self) -> bool:
        """Three or more channels with blue dominant, as a tangent-space normal map (flat: 128, 128, 255)."""
        if self.pixels.shape[2] < 3:
            return False
        step = max(1, int(np.sqrt(self.pixels.shape[0] * self.pixels.shape[1] / 65536)))
        red, green, blue = self.pixels[::step, ::step, :3].reshape(-1, 3).mean(axis=0)
        return blue >= 0.7 * 255 and blue > red and blue > green


_cache: OrderedDict = OrderedDict()
_cache_lock = threading.Lock()


def header_or_reason(path: str) -> tuple[ImageHeader | None, str | None]:
    """The header of the texture ``path``, or None and why not (``"missing"``, ``"a Git LFS pointer"``, ...)."""
    try:
        return read_header(path), None
    except ImageUnreadable as err:
        return None, str(err)


def why_not_decoded(path: str | None, budget: int = DECODE_BUDGET) -> str | None:
    """Why :func:`decode` would refuse ``path``, read from its header alone (no path, no readable header,
    over ``budget``, a format not decoded), else None. A file whose header is fine may still fail to decode."""
    if path is None:
        return "no texture"
    header, reason = header_or_reason(path)
    if header is None:
        return reason
    if header.pixels > budget:
        return f"{header.width}x{header.height} is over the decode budget of {budget:,} pixels"
    if header.format not in _PLUGINS:
        return f"{header.format} texels are not decoded"
    return None


def decode(path: str, budget: int = DECODE_BUDGET) -> DecodedTexture:
    """The texture at ``path`` decoded (cached for the run, see the module's notes).

    Raises :class:`TextureUnusable` naming why it is not decoded: no readable header, more pixels
    than ``budget``, a format not decoded here, or a file that does not decode.
    """
    header, _ = header_or_reason(path)
    refused = why_not_decoded(path, budget)
    if refused is not None:
        raise TextureUnusable(refused + (", not decoded" if header is not None else ""), header)
    try:
        stat = os.stat(path)
    except OSError as err:
        raise TextureUnusable(f"not readable ({err.__class__.__name__})", header) from None
    key = (os.path.realpath(path), stat.st_size, stat.st_mtime_ns)
    with _cache_lock:
        if key in _cache:
            _cache.move_to_end(key)
            return _cache[key]
    texture = DecodedTexture(path, header, _decode_pixels(path, header))
    with _cache_lock:
        _cache[key] = texture
        while sum(t.pixels.nbytes for t in _cache.values()) > CACHE_BYTES and len(_cache) > 1:
            _cache.popitem(last=False)
    return texture


#: Pillow's image class per header format, opened directly: ``Image.open`` would first import every common
#: plug-in (JPEG's imports subprocess), a tenth of a second of a small check.
_PLUGINS = {"PNG": ("PngImagePlugin", "PngImageFile"), "JPEG": ("JpegImagePlugin", "JpegImageFile"),
            "BMP": ("BmpImagePlugin", "BmpImageFile"), "TGA": ("TgaImagePlugin", "TgaImageFile"),
            "TIFF": ("TiffImagePlugin", "TiffImageFile"), "DDS": ("DdsImagePlugin", "DdsImageFile")}


def _opened(file, header: ImageHeader):
    """The Pillow image of an open texture file, by the class of its header's format."""
    import importlib

    module, name = _PLUGINS[header.format]
    return getattr(importlib.import_module(f"PIL.{module}"), name)(file)


def _decode_pixels(path: str, header: ImageHeader) -> np.ndarray:
    """(H, W, C) uint8 of an image whose header was checked against the budget."""
    from PIL import Image, UnidentifiedImageError

    try:
        with open_image_file(path) as file, _opened(file, header) as image:
            if image.size != header.size:
                raise TextureUnusable(f"its header and its decoder disagree on the size ({image.size})", header)
            bands = image.getbands()
            mode = ("RGBA" if "A" in bands else "RGB") if len(bands) >= 3 else ("LA" if "A" in bands else "L")
            if image.mode in ("I;16", "I;16B", "I;16L", "I"):  # 16-bit grey: keep the top 8 bits
                array = (np.asarray(image, dtype=np.uint32) >> 8).astype(np.uint8)
            else:
                array = np.asarray(image if image.mode == mode else image.convert(mode), dtype=np.uint8)
    except TextureUnusable:
        raise
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError, Image.DecompressionBombError) as err:
        raise TextureUnusable(f"does not decode ({err.__class__.__name__})", header) from None
    array = array.reshape(*array.shape[:2], -1)
    array.flags.writeable = False
    return array
