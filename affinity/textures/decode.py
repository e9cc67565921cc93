"""Decode a texture once per run, within a pixel budget checked against its header first.

A texture whose header claims more than :data:`DECODE_BUDGET` pixels is never
decoded (a 100,000 x 100,000 PNG header would ask for 30 GB); decoded textures
are kept as (H, W, 4) uint8 (four bytes a texel, as Pillow holds them), at most :data:`CACHE_BYTES` of them and
their pyramids at a time (least recently used dropped first), keyed by path, size and modification time,
so each texture is decoded once per run however many meshes or rules read it.
Peak memory for textures: :data:`CACHE_BYTES` plus one texture being decoded
(at most ``DECODE_BUDGET x 4`` bytes, twice while Pillow hands its copy over) and its min/max
pyramids (2/3 of it at most, built only over the rows the lint's queries reach).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass
from functools import cached_property, partial

import numpy as np

from ..loaders.imagesize import ImageHeader, ImageUnreadable, image_identity, open_image_file, read_header
from .held import held_texture

#: Pixels (width x height) a texture may have to be decoded: 8192 x 8192.
DECODE_BUDGET = 1 << 26
#: Bytes of decoded textures and their pyramids kept between meshes of one run: four 4096 x 4096 textures.
#: A folder run's peak is about this plus one mesh's work, whatever the number of meshes (measured in
#: benchmarks/bench_texture_memory.py; 512 MiB let 32 meshes with their own 4K textures peak at 1.6x 4's).
CACHE_BYTES = 1 << 28


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
    texels : (H, W, 4) uint8, C-contiguous, read-only: one 32-bit word a texel, as Pillow holds an image
        (the sampler gathers words); its first ``channels`` bytes are the texture's; row 0 the top
    channels : C, 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA)
    """

    path: str
    header: ImageHeader
    texels: np.ndarray
    channels: int

    def boxed(self, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Texel boxes as repeat wrapping reads them: unchanged (:class:`affinity.textures.wrapping.WrappedTexture`
        moves them for other wrap modes)."""
        return low, high

    @property
    def held_bytes(self) -> int:
        """Bytes the texture holds: its texels and the bands of its pyramids built so far (the decode cache's
        measure: the pyramids of a texture read all over hold about 1.3 times its texels)."""
        pyramids = [vars(self).get("pyramid"), *vars(self).get("slopes", ())]
        return self.texels.nbytes + sum(p.built_bytes for p in pyramids if p is not None)

    @property
    def pixels(self) -> np.ndarray:
        """(H, W, C) uint8, read-only: the texture's channels of :attr:`texels` (a view)."""
        return self.texels[..., :self.channels]

    @cached_property
    def pyramid(self):
        """The texture's min/max pyramid (:class:`~affinity.textures.filtering.RangePyramid`), reduced as
        queries reach its parts."""
        from .filtering import RangePyramid

        return RangePyramid(self.texels, channels=self.channels)

    @cached_property
    def slopes(self):
        """The pyramids of the texture's steps to the next column and to the next row, wrapping
        (:class:`~affinity.textures.filtering.RangePyramid` of (H, W, 1) uint8, maxima): the largest channel
        difference from each texel to that neighbour; bilinear filtering changes by at most their sum per
        texel moved. The steps are computed for the rows queries reach."""
        from .filtering import RangePyramid

        # The pyramids hold the texels, not the texture: a bound method would make a cycle (texture ->
        # pyramid -> method -> texture) that only the cyclic collector frees, long after the cache dropped it.
        height, width = self.texels.shape[:2]
        return tuple(RangePyramid(minima=False, rows=partial(_channel_steps, self.texels, axis=axis),
                                  fold=partial(_largest_step, channels=self.channels), shape=(height, width, 1))
                     for axis in (1, 0))

    @cached_property
    def packed(self):
        """The texels packed for sampling (:class:`~affinity.textures.filtering.PackedTexture`): the
        :attr:`texels` themselves."""
        from .filtering import PackedTexture

        return PackedTexture(self.texels, self.channels)

    @cached_property
    def looks_like_normal_map(self) -> bool:
        """Three or more channels with blue dominant, as a tangent-space normal map (flat: 128, 128, 255)."""
        if self.pixels.shape[2] < 3:
            return False
        step = max(1, int(np.sqrt(self.pixels.shape[0] * self.pixels.shape[1] / 65536)))
        red, green, blue = self.pixels[::step, ::step, :3].reshape(-1, 3).mean(axis=0)
        return blue >= 0.7 * 255 and blue > red and blue > green


def _channel_steps(texels: np.ndarray, start: int, stop: int, axis: int) -> np.ndarray:
    """(stop - start, W, 4) uint8: per channel of ``texels`` (H, W, 4) uint8, |difference| from each texel of
    rows ``start`` to ``stop`` to the next one along ``axis`` (1: the next column, 0: the next row), wrapping.
    Whole four-byte texels are subtracted: contiguous, and no reduction per texel."""
    rows = texels[start:stop]
    steps = np.empty_like(rows)
    if axis == 1:  # the last column wraps to the first
        pairs = ((rows[:, :-1], rows[:, 1:], steps[:, :-1]), (rows[:, -1:], rows[:, :1], steps[:, -1:]))
    else:  # the last row wraps to the first
        pairs = ((rows[:-1], texels[start + 1:stop], steps[:-1]),
                 (rows[-1:], texels[stop % len(texels)][None], steps[-1:]))
    for texel, neighbour, out in pairs:  # |a - b| in uint8, no copy of the neighbours
        np.maximum(texel, neighbour, out=out)
        out -= np.minimum(texel, neighbour)
    return steps


def _largest_step(steps: np.ndarray, channels: int) -> np.ndarray:
    """(..., 1) uint8: the largest of :func:`_channel_steps`'s (..., 4) over the texture's first ``channels``
    (elementwise: faster than a reduction over a short axis)."""
    largest = steps[..., :1].copy()
    for channel in range(1, channels):
        np.maximum(largest, steps[..., channel:channel + 1], out=largest)
    return largest


_cache: OrderedDict = OrderedDict()
_cache_lock = threading.Lock()


def header_or_reason(path: str) -> tuple[ImageHeader | None, str | None]:
    """The header of the texture ``path`` (a held one's, :mod:`~affinity.textures.held`), or None and why not
    (``"missing"``, ``"a Git LFS pointer"``, ...)."""
    held = held_texture(path)
    if held is not None:
        return held.header, None
    try:
        return read_header(path), None
    except ImageUnreadable as err:
        return None, str(err)


def why_not_decoded(path: str | None, budget: int = DECODE_BUDGET) -> str | None:
    """Why :func:`decode` would refuse ``path``, read from its header alone (no path, no readable header,
    over ``budget``, a format not decoded), else None. A file whose header is fine may still fail to decode."""
    if path is None:
        return "no texture"
    if held_texture(path) is not None:
        return None
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
    than ``budget``, a format not decoded here, or a file that does not decode. A held texture
    (:mod:`~affinity.textures.held`) is returned as it is held.
    """
    held = held_texture(path)
    if held is not None:
        return held
    header, _ = header_or_reason(path)
    refused = why_not_decoded(path, budget)
    if refused is not None:
        raise TextureUnusable(refused + (", not decoded" if header is not None else ""), header)
    try:
        key = image_identity(path)
    except OSError as err:
        raise TextureUnusable(f"not readable ({err.__class__.__name__})", header) from None
    with _cache_lock:
        if key in _cache:
            _cache.move_to_end(key)
            return _cache[key]
        _evict(header.width * header.height * 4)  # room first: the texture and the one it replaces never both
    texture = DecodedTexture(path, header, *_decode_texels(path, header))
    with _cache_lock:
        _cache[key] = texture
        _evict(0)
    return texture


def _evict(incoming: int) -> None:
    """Drop the least recently used textures until those kept and ``incoming`` bytes fit :data:`CACHE_BYTES`
    (the last one kept whatever its size), and hand the memory they freed back to the system. Called holding
    the cache's lock."""
    evicted = False
    while _cache and sum(t.held_bytes for t in _cache.values()) + incoming > CACHE_BYTES and (
            incoming or len(_cache) > 1):
        _cache.popitem(last=False)
        evicted = True
    if evicted:
        _trim_heap()


def _trim_heap() -> None:
    """Return the heap's free memory to the system (glibc ``malloc_trim``; a no-op elsewhere). A texture's
    pyramid levels are under glibc's mmap threshold (16 MiB at 4096 x 4096): freed, they stay with the process
    (``affinity check`` keeps up to 256 MiB of freed heap for the parser's temporaries), and a folder of
    textures grew by them."""
    import ctypes

    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (OSError, AttributeError):
        pass


#: Pillow's image class per header format, opened directly: ``Image.open`` would first import every common
#: plug-in (JPEG's imports subprocess), a tenth of a second of a small check. The formats Pillow decodes: an
#: EXR's size comes from its header, its texels are not read.
_PLUGINS = {"PNG": ("PngImagePlugin", "PngImageFile"), "JPEG": ("JpegImagePlugin", "JpegImageFile"),
            "BMP": ("BmpImagePlugin", "BmpImageFile"), "TGA": ("TgaImagePlugin", "TgaImageFile"),
            "TIFF": ("TiffImagePlugin", "TiffImageFile"), "DDS": ("DdsImagePlugin", "DdsImageFile")}


def _opened(file, header: ImageHeader):
    """The Pillow image of an open texture file, by the class of its header's format."""
    import importlib

    module, name = _PLUGINS[header.format]
    return getattr(importlib.import_module(f"PIL.{module}"), name)(file)


def _decode_texels(path: str, header: ImageHeader) -> tuple[np.ndarray, int]:
    """(H, W, 4) uint8 texels (:attr:`DecodedTexture.texels`) and the channel count C of an image whose
    header was checked against the budget. Colour images come from Pillow four bytes a texel, as it holds
    them (no copy past its own); grey ones are padded."""
    from PIL import Image, UnidentifiedImageError

    try:
        with open_image_file(path) as file, _opened(file, header) as image:
            if image.size != header.size:
                raise TextureUnusable(f"its header and its decoder disagree on the size ({image.size})", header)
            bands = image.getbands()
            mode = ("RGBA" if "A" in bands else "RGB") if len(bands) >= 3 else ("LA" if "A" in bands else "L")
            if image.mode in ("I;16", "I;16B", "I;16L", "I"):  # 16-bit grey: keep the top 8 bits
                array = (np.asarray(image, dtype=np.uint32) >> 8).astype(np.uint8)
            elif mode in ("RGB", "RGBA"):
                texels = _decoded_in_place(image) if header.format == "PNG" and image.mode == mode else None
                if texels is not None:
                    return texels, len(mode)
                image = image if image.mode == mode else image.convert(mode)
                raw = image.tobytes("raw", "RGBX" if mode == "RGB" else "RGBA")
                texels = np.frombuffer(raw, dtype=np.uint8).reshape(image.height, image.width, 4)
                return texels, len(mode)  # frombuffer of bytes: already read-only
            else:
                array = np.asarray(image if image.mode == mode else image.convert(mode), dtype=np.uint8)
    except TextureUnusable:
        raise
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError, Image.DecompressionBombError) as err:
        raise TextureUnusable(f"does not decode ({err.__class__.__name__})", header) from None
    array = array.reshape(*array.shape[:2], -1)
    texels = np.zeros((*array.shape[:2], 4), dtype=np.uint8)
    texels[..., :array.shape[2]] = array
    texels.flags.writeable = False
    return texels, array.shape[2]


def _decoded_in_place(image) -> np.ndarray | None:
    """(H, W, 4) uint8: the PNG ``image`` (mode RGB or RGBA, not loaded yet) decoded by Pillow straight into a
    numpy buffer laid out as Pillow holds such images (four bytes a texel), saving the copy out of Pillow's
    memory (a fifth of the decode's time at 2048 x 2048); None where this Pillow does not map a buffer
    (``Image.core.map_buffer`` is its own, not public: the copying path then decodes)."""
    from PIL import Image

    width, height = image.size
    texels = np.empty((height, width, 4), dtype=np.uint8)
    try:
        image.im = Image.core.map_buffer(texels, image.size, "raw", 0, (image.mode, width * 4, 1))
    except (AttributeError, TypeError, ValueError):
        return None
    image.load()
    texels.flags.writeable = False
    return texels
