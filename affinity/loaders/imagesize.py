"""Image dimensions from file headers, without decoding and without Pillow.

``affinity check`` needs every bound texture's size for the texel unit and must
check an image's size against the decode budget before anything decodes it, so
the few header bytes are read by hand: PNG, JPEG, BMP, TGA, TIFF (tiled ``.tx``
and BigTIFF too), OpenEXR and DDS. Every texture file is opened by
:func:`open_image_file`, the one place that opens them.
"""

from __future__ import annotations

import io
import os
import struct
from collections import OrderedDict
from dataclasses import dataclass

from .regular import RefusedFile
from .sidefiles import open_side_file

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# JPEG start-of-frame markers: C0-CF except DHT (C4), JPG (C8) and DAC (CC).
_JPEG_FRAME_MARKERS = frozenset(range(0xC0, 0xD0)) - {0xC4, 0xC8, 0xCC}
# Markers without a length field: TEM and the restart markers RST0-7.
_JPEG_STANDALONE_MARKERS = frozenset([0x01, *range(0xD0, 0xD8)])
_TGA_IMAGE_TYPES = frozenset([1, 2, 3, 9, 10, 11])
_TGA_PIXEL_DEPTHS = frozenset([8, 15, 16, 24, 32])
_EXR_MAGIC = b"\x76\x2f\x31\x01"
_LFS_POINTER = b"version https://git-lfs.github.com/spec/"
#: TIFF tags ImageWidth and ImageLength; field types SHORT, LONG and LONG8 (BigTIFF).
_TIFF_WIDTH, _TIFF_LENGTH = 256, 257
_TIFF_TYPES = {3: "H", 4: "I", 16: "Q"}
#: An EXR header attribute's name and type are at most this long (the format allows 255 bytes each).
_EXR_NAME_LIMIT = 256


class ImageUnreadable(Exception):
    """An image file whose header cannot be read; the message is the reason, for a note
    (``"missing"``, ``"a Git LFS pointer"``, ``"not a readable image"``)."""


@dataclass(frozen=True)
class ImageHeader:
    """What an image file's header says: ``width`` and ``height`` in pixels and the ``format``
    (``"PNG"``, ``"JPEG"``, ``"BMP"``, ``"TGA"``, ``"TIFF"``, ``"EXR"``, ``"DDS"``)."""

    width: int
    height: int
    format: str

    @property
    def size(self) -> tuple[int, int]:
        return self.width, self.height

    @property
    def pixels(self) -> int:
        return self.width * self.height


#: Images a mesh file holds inside it (FBX embedded media), by the path its texture maps name them with
#: (:func:`embed`); read from memory. At most :data:`EMBEDDED_BYTES` of them are kept, the oldest dropped first.
EMBEDDED: OrderedDict[str, bytes] = OrderedDict()
EMBEDDED_BYTES = 1 << 29


def embed(path: str, content: bytes) -> None:
    """Keep the image ``content`` that a mesh file embeds under the (not existing) file name ``path``."""
    EMBEDDED.pop(path, None)
    EMBEDDED[path] = content
    while sum(map(len, EMBEDDED.values())) > EMBEDDED_BYTES and len(EMBEDDED) > 1:
        EMBEDDED.popitem(last=False)


def open_image_file(path: str | os.PathLike):
    """Open a texture file for reading bytes: the one place texture files are opened (header
    reading and decoding alike), so a policy on what may be opened (regular files only, a size
    budget) applies to both, and a file is opened once for every header read and its decode
    (:mod:`.sidefiles`); an embedded image (:func:`embed`) opens from memory. Raises OSError."""
    content = EMBEDDED.get(os.fspath(path))
    return io.BytesIO(content) if content is not None else open_side_file(path)


def image_identity(path: str | os.PathLike) -> tuple:
    """What tells one version of the image ``path`` from another, for caches: the real path, size and
    modification time of a file; the name and content of an embedded image. Raises OSError."""
    content = EMBEDDED.get(os.fspath(path))
    if content is not None:
        return os.fspath(path), len(content), hash(content)
    stat = os.stat(path)
    return os.path.realpath(path), stat.st_size, stat.st_mtime_ns


def read_header(path: str | os.PathLike) -> ImageHeader:
    """The header of the image file ``path``.

    TGA has no signature, so it is recognised only by a ``.tga`` extension and a
    plausible header. Raises :class:`ImageUnreadable` naming why not.
    """
    try:
        with open_image_file(path) as file:
            head = file.read(64)
            if head.startswith(_LFS_POINTER):
                raise ImageUnreadable("a Git LFS pointer")
            header = _parse(file, head, str(path).lower())
    except FileNotFoundError:
        raise ImageUnreadable("missing") from None
    except RefusedFile as err:  # a FIFO, a device: its kind is the reason
        raise ImageUnreadable(err.strerror) from None
    except (OSError, struct.error, ValueError, IndexError):
        header = None
    if header is None or header[0] <= 0 or header[1] <= 0:
        raise ImageUnreadable("not a readable image")
    return ImageHeader(int(header[0]), int(header[1]), header[2])


def image_size(path: str | os.PathLike | None) -> tuple[int, int] | None:
    """(width, height) of an image :func:`read_header` reads, or None (no path, a missing or
    unreadable file, or a header of no known format)."""
    if path is None:
        return None
    try:
        return read_header(path).size
    except ImageUnreadable:
        return None


def _parse(file, head: bytes, name: str) -> tuple[int, int, str] | None:
    """(width, height, format) from the first bytes ``head`` of ``file`` (read further as needed)."""
    if head.startswith(_PNG_SIGNATURE) and head[12:16] == b"IHDR":
        return (*struct.unpack(">II", head[16:24]), "PNG")
    if head.startswith(b"\xff\xd8"):
        size = _jpeg_size(file)
        return None if size is None else (*size, "JPEG")
    if head.startswith(b"BM"):
        return (*_bmp_size(head), "BMP")
    if head[:4] in (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+"):
        size = _tiff_size(file, head)
        return None if size is None else (*size, "TIFF")
    if head.startswith(_EXR_MAGIC):
        size = _exr_size(file)
        return None if size is None else (*size, "EXR")
    if head.startswith(b"DDS ") and len(head) >= 20:
        height, width = struct.unpack("<II", head[12:20])
        return width, height, "DDS"
    if name.endswith(".tga"):
        size = _tga_size(head)
        return None if size is None else (*size, "TGA")
    return None


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
        if length < 2:
            return None
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


def _tiff_size(file, head: bytes) -> tuple[int, int] | None:
    """ImageWidth and ImageLength of the first image file directory (TIFF 6.0 §2; BigTIFF: 8-byte
    offsets and counts, 20-byte entries). Tiled TIFF (``.tx``) keeps the same two tags."""
    order = "<" if head[:2] == b"II" else ">"
    big = struct.unpack(order + "H", head[2:4])[0] == 43
    offset = struct.unpack(order + "Q", head[8:16])[0] if big else struct.unpack(order + "I", head[4:8])[0]
    file.seek(offset)
    count_format, entry_size = ("Q", 20) if big else ("H", 12)
    (entries,) = struct.unpack(order + count_format, file.read(struct.calcsize(count_format)))
    table = file.read(entries * entry_size)
    size = {}
    for k in range(entries):
        entry = table[k * entry_size : (k + 1) * entry_size]
        tag, kind = struct.unpack(order + "HH", entry[:4])
        if tag in (_TIFF_WIDTH, _TIFF_LENGTH) and kind in _TIFF_TYPES:
            value = entry[12:] if big else entry[8:]
            size[tag] = struct.unpack_from(order + _TIFF_TYPES[kind], value)[0]
    if _TIFF_WIDTH not in size or _TIFF_LENGTH not in size:
        return None
    return size[_TIFF_WIDTH], size[_TIFF_LENGTH]


def _exr_size(file) -> tuple[int, int] | None:
    """The ``dataWindow`` (box2i: xMin, yMin, xMax, yMax) of an OpenEXR header (of its first part)."""
    file.seek(8)  # magic number and version field
    while True:
        name, kind = _exr_string(file), None
        if not name:
            return None  # the header ended without a dataWindow
        kind = _exr_string(file)
        (length,) = struct.unpack("<i", file.read(4))
        if name == b"dataWindow" and kind == b"box2i" and length == 16:
            x_min, y_min, x_max, y_max = struct.unpack("<iiii", file.read(16))
            return x_max - x_min + 1, y_max - y_min + 1
        if length < 0:
            return None
        file.seek(length, os.SEEK_CUR)


def _exr_string(file) -> bytes:
    """A null-terminated string of an EXR header (empty at the header's end or at end of file)."""
    chars = bytearray()
    while len(chars) < _EXR_NAME_LIMIT:
        char = file.read(1)
        if char in (b"", b"\x00"):
            return bytes(chars)
        chars += char
    raise ValueError("EXR attribute name too long")
