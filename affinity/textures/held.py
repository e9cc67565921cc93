"""Textures another program has decoded, held in memory under names that are not files.

Inside Blender the texels come from Blender's own images (``bpy.types.Image``), not from
files decoded here (design.md: the add-on never imports Pillow). The Blender converter names
each image by a key that is no path on disk (:data:`PREFIX`), lists it in the mesh's
``material_maps`` like a file, and holds the decoded texels under that key while the lint
runs (:func:`holding`). :func:`affinity.textures.decode.decode` and the texel grid's header
lookup answer from here first, so every reading (the texel unit, the visible reading, a
fix's re-lint) reads the held texels exactly as it reads a decoded file. A UDIM image is held
tile by tile under its key with the token replaced by the tile number, as
:func:`affinity.textures.binding.bound_textures` names a tile that has no file.
"""

from __future__ import annotations

import threading
from contextlib import contextmanager

#: Keys of held textures start with this: no file path does.
PREFIX = "held://"

_held: dict = {}
_lock = threading.Lock()


def held_texture(path: str):
    """The :class:`~affinity.textures.decode.DecodedTexture` held under ``path``, or None."""
    with _lock:
        return _held.get(path)


@contextmanager
def holding(textures: dict):
    """Hold ``textures`` (key -> DecodedTexture, keys starting with :data:`PREFIX`) for the ``with``
    block; what the keys held before comes back after it (nested holds of the same key stack)."""
    bad = [key for key in textures if not key.startswith(PREFIX)]
    if bad:
        raise ValueError(f"held texture keys must start with {PREFIX!r}: {bad[0]!r}")
    with _lock:
        before = {key: _held.get(key) for key in textures}
        _held.update(textures)
    try:
        yield
    finally:
        with _lock:
            for key, texture in before.items():
                if texture is None:
                    _held.pop(key, None)
                else:
                    _held[key] = texture
