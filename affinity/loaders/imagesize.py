"""Image dimensions from file headers (PNG, JPEG, BMP, TGA), without Pillow.

``affinity check`` needs the ``map_Kd`` texture's size for the texel unit and must
not import Pillow, so the few header bytes are read by hand.
"""

from __future__ import annotations

import os
import struct

from .regular import open_regular

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# JPEG start-of-frame markers: C0-CF except DHT (C4), JPG (C8) and DAC (CC).
_JPEG_FRAME_MARKERS = frozenset(range(0xC0, 0xD0)) - {0xC4, 0xC8, 0xCC}
# Markers without a length field: TEM and the restart markers RST0-7.
_JPEG_STANDALONE_MARKERS = frozenset([0x01, *range(0xD0, 0xD8)])
_TGA_IMAGE_TYPES = frozenset([1, 2, 3, 9, 10, 11])
_TGA_PIXEL_DEPTHS = frozenset([8, 15, 16, 24, 32])


def image_size(path: str | os.PathLike | None) -> tuple[int, int] | None:
    """(width, height) of a PNG, JPEG, BMP or TGA image, or None.

    None when ``path`` is None, the file is missing or unreadable, or its header is
    not one of these formats. TGA has no signature, so it is recognised only by a
    ``.tga`` extension and a plausible header.
    """
    if path is None:
        return None
    try:
        with open_regular(path) as file:
            head = file.read(32)
            if head.startswith(_PNG_SIGNATURE) and head[12:16] == b"IHDR":
                size = struct.unpack(">II", head[16:24])
            elif head.startswith(b"\xff\xd8"):
                size = _jpeg_size(file)
            elif head.startswith(b"BM"):
                size = _bmp_size(head)
            elif str(path).lower().endswith(".tga"):
                size = _tga_size(head)
            else:
                size = None
    except (OSError, struct.error):
        return None
    if size is None or min(size) <= 0:
        return None
    return int(size[0]), int(size[1])


def _jpeg_size(file) -> tuple[int, int] | None:
    """Walk the JPEG marker segments up to the first start-of-frame."""
    file.seek(2)
    while True:
        if file.read(1) != b"\xff":
            return None
        marker = file.read(1)
        while marker == b"\xff":  # fill bytes
            marker = file.read(1)
        if not marker:
            return None
        code = marker[0]
        if code in _JPEG_STANDALONE_MARKERS:
            continue
        if code in (0xD9, 0xDA):  # end of image or start of scan before any frame
            return None
        (length,) = struct.unpack(">H", file.read(2))
        if code in _JPEG_FRAME_MARKERS:
            _precision, height, width = struct.unpack(">BHH", file.read(5))
            return width, height
        file.seek(length - 2, os.SEEK_CUR)


def _bmp_size(head: bytes) -> tuple[int, int]:
    """BITMAPCOREHEADER (12 bytes, unsigned 16-bit) or the later headers (signed 32-bit;
    a negative height means top-down rows)."""
    (header_size,) = struct.unpack("<I", head[14:18])
    if header_size == 12:
        return struct.unpack("<HH", head[18:22])
    width, height = struct.unpack("<ii", head[18:26])
    return width, abs(height)


def _tga_size(head: bytes) -> tuple[int, int] | None:
    if len(head) < 18 or head[1] not in (0, 1) or head[2] not in _TGA_IMAGE_TYPES:
        return None
    if head[16] not in _TGA_PIXEL_DEPTHS:
        return None
    return struct.unpack("<HH", head[12:16])
