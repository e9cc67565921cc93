"""Blender's images as the texels the lint reads: ``bpy.types.Image`` decoded by Blender, never by Pillow.

:func:`held_textures` turns the images a mesh's materials read into
:class:`~affinity.textures.decode.DecodedTexture` records held under keys that are no file
(:mod:`affinity.textures.held`): the same (H, W, 4) uint8 texels, row 0 the top, that
decoding the image's file gives on the command line.

- ``Image.pixels.foreach_get`` fills one float32 buffer (no Python object per texel). Blender
  keeps rows bottom-up: they are flipped. A byte image's pixels are its stored bytes / 255 (for an
  sRGB PNG, the file's own 8-bit values), so rounding x 255 gives them back exactly. A float image
  (EXR, 16-bit PNG) holds scene-linear values: colour data is encoded with the sRGB curve, data
  (Non-Color) kept, then rounded to 8 bits (a 16-bit PNG then reads within one step of the top
  8 bits the command line keeps).
- A UDIM image (source ``TILED``) is read tile by tile, each at its own size: ``Image.pixels``
  gives the first tile only, so the image is saved to a temporary folder (``Image.save`` with a
  path writes every tile and changes nothing of the image) and each tile is loaded back as an
  image of its own (``bpy.data.images.load``), read and removed.
- Packed and generated images read the same way: Blender holds their pixels.

``bpy`` is imported only by the functions that load tiles.
"""

from __future__ import annotations

import os
import tempfile

import numpy as np

from ..loaders.imagesize import ImageHeader
from ..textures.decode import DECODE_BUDGET, DecodedTexture
from ..textures.held import PREFIX

UDIM_TOKEN = "<UDIM>"


def image_key(image) -> str:
    """The held key of a Blender image (a UDIM image's holds the token, its tiles' the tile number)."""
    key = PREFIX + image.name_full
    return key + "." + UDIM_TOKEN if image.source == "TILED" else key


def pixels_to_texels(pixels: np.ndarray, width: int, height: int, linear: bool) -> np.ndarray:
    """(H, W, 4) uint8, row 0 the top: Blender's ``Image.pixels`` (H * W * 4,) float32, rows bottom-up.

    ``linear``: the values are scene-linear colour (a float image that is not data): encoded with the
    sRGB transfer function (IEC 61966-2-1) before rounding.

    >>> pixels_to_texels(np.array([0, 0, 0, 1, 1, 1, 1, 1], np.float32), 1, 2, False)[:, 0].tolist()
    [[255, 255, 255, 255], [0, 0, 0, 255]]
    >>> pixels_to_texels(np.array([0.2158605, 0.5028865, 0.0030353, 1], np.float32), 1, 1, True)[0, 0].tolist()
    [128, 188, 10, 255]
    """
    rgba = np.asarray(pixels, dtype=np.float32).reshape(height, width, 4)[::-1]
    if linear:
        rgb = np.clip(rgba[..., :3], 0.0, 1.0)
        encoded = np.where(rgb <= 0.0031308, 12.92 * rgb, 1.055 * np.power(rgb, 1 / 2.4) - 0.055)
        rgba = np.concatenate([encoded, rgba[..., 3:]], axis=-1)
    texels = np.rint(np.clip(rgba, 0.0, 1.0) * 255.0).astype(np.uint8)
    texels.flags.writeable = False
    return texels


def image_channels(image) -> int:
    """The channels the image's data has (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA), from its bits per
    pixel (``Image.depth``: 8 bits a byte channel, 32 a float one); ``Image.channels`` is 4 for all."""
    bits = 32 if image.is_float else 8
    return min(max(image.depth // bits, 1), 4)


def decoded_image(image, key: str) -> DecodedTexture:
    """A single (not tiled) Blender image as a held :class:`DecodedTexture` under ``key``.

    Raises ValueError naming why it cannot be read (no pixels, over the decode budget).
    """
    width, height = (int(n) for n in image.size)
    if width * height == 0:  # asking for the size loads the image; a missing file has none
        raise ValueError(f"image {image.name!r} has no pixels (missing file?)")
    if width * height > DECODE_BUDGET:
        raise ValueError(f"image {image.name!r}: {width}x{height} is over the decode budget of "
                         f"{DECODE_BUDGET:,} pixels")
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    linear = bool(image.is_float) and not image.colorspace_settings.is_data
    texels = pixels_to_texels(pixels, width, height, linear)
    channels = image_channels(image)
    if channels == 2:  # Blender spreads grey over R, G and B: the core reads grey, alpha
        texels = texels.copy()
        texels[..., 1] = texels[..., 3]
        texels.flags.writeable = False
    return DecodedTexture(key, ImageHeader(width, height, image.file_format), texels, channels)


def decoded_tiles(image) -> dict[str, DecodedTexture]:
    """Every tile of a UDIM image, each decoded at its own size, under the image's key with the tile number
    for the token (module docstring: saved to a temporary folder, each tile loaded back)."""
    import bpy

    key = image_key(image)
    tiles = {}
    with tempfile.TemporaryDirectory() as folder:
        try:
            image.save(filepath=os.path.join(folder, "tile." + UDIM_TOKEN + ".png"))
        except RuntimeError as err:
            raise ValueError(f"UDIM image {image.name!r} could not be read ({err})") from None
        for tile in image.tiles:
            path = os.path.join(folder, f"tile.{tile.number}.png")
            if not os.path.isfile(path):
                continue
            loaded = bpy.data.images.load(path, check_existing=False)
            tile_key = key.replace(UDIM_TOKEN, str(tile.number))
            try:
                loaded.colorspace_settings.name = image.colorspace_settings.name
                tiles[tile_key] = decoded_image(loaded, tile_key)
            finally:
                bpy.data.images.remove(loaded)
    return tiles


def held_textures(images) -> tuple[dict[str, DecodedTexture], list[str]]:
    """The texels of Blender ``images`` (each once), key -> DecodedTexture, and a note per image that
    could not be read."""
    textures, notes = {}, []
    for image in {image.name_full: image for image in images}.values():
        try:
            if image.source == "TILED":
                textures.update(decoded_tiles(image))
            else:
                textures[image_key(image)] = decoded_image(image, image_key(image))
        except ValueError as err:
            notes.append(f"{err}: its findings stay in texels")
    return textures, notes
