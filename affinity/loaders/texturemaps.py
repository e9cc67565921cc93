"""The textures a mesh's uv set feeds, by role (design.md, "Textures by role").

Each loader lists, per material, the texture maps the material reads through the
mesh's uv: :class:`TextureMap` records in ``Mesh.material_maps``. An OBJ reads
them from its MTL libraries (:func:`affinity.loaders.mtl.obj_material_maps`), a USD stage from
UsdPreviewSurface and MaterialX networks (:mod:`affinity.loaders.usdmaterials`).
A map's path may hold a UDIM token (``<UDIM>``, ``%(UDIM)d``): each tile is then
its own file and size (:func:`udim_tiles`, :func:`udim_tile_of`).
"""

from __future__ import annotations

import glob
import os
import re
from dataclasses import dataclass

import numpy as np

#: The roles in the order the worst of them decides a finding when values tie (design.md).
ROLES = ("base colour", "normal", "height", "scalar")
_UDIM_TOKENS = ("<UDIM>", "<udim>", "%(UDIM)d")


@dataclass(frozen=True, kw_only=True)
class TextureMap:
    """One texture a material reads through the mesh's uv.

    Attributes
    ----------
    role : ``"base colour"``, ``"normal"``, ``"height"`` or ``"scalar"`` (None: a map whose texels no
        reading knows, named by a role registered without a kind)
    path : the file, resolved (it may hold a UDIM token)
    name : the file as the material spells it
    source : what names it, for messages: ``"map_Kd"``, ``"UsdUVTexture /Looks/Wood/Tex"``
    scale, offset, rotation : the texture is read at ``R(rotation) (uv * scale) + offset``, R a rotation by
        ``rotation`` degrees counter-clockwise (MTL ``-s``/``-o``; MaterialX ``uvtiling``/``uvoffset``; USD
        ``UsdTransform2d``: scale, then rotate, then translate)
    wrap : what is read outside [0, 1] along u and v: ``repeat``, ``clamp``, ``mirror`` or ``black``
        (:mod:`affinity.textures.wrapping`; MTL ``-clamp on``, UsdUVTexture ``wrapS``/``wrapT``, MaterialX
        ``uaddressmode``/``vaddressmode``)
    """

    role: str | None
    path: str
    name: str
    source: str
    scale: tuple[float, float] = (1.0, 1.0)
    offset: tuple[float, float] = (0.0, 0.0)
    rotation: float = 0.0
    wrap: tuple[str, str] = ("repeat", "repeat")

    @property
    def udim(self) -> bool:
        return any(token in self.path for token in _UDIM_TOKENS)

    def texture_uv(self, uv: np.ndarray) -> np.ndarray:
        """(..., 2) float64: where the texture is read for mesh uv ``uv`` (..., 2).

        >>> TextureMap(role="base colour", path="t.png", name="t.png", source="UsdUVTexture", scale=(2.0, 0.5),
        ...            rotation=90.0, offset=(0.25, 0.1)).texture_uv(np.array([0.1, 0.2])).round(12).tolist()
        [0.15, 0.3]
        """
        if self.scale == (1.0, 1.0) and self.offset == (0.0, 0.0) and self.rotation == 0.0:
            return uv
        uv = uv * np.asarray(self.scale)
        if self.rotation:
            cosine, sine = np.cos(np.radians(self.rotation)), np.sin(np.radians(self.rotation))
            uv = np.stack([cosine * uv[..., 0] - sine * uv[..., 1], sine * uv[..., 0] + cosine * uv[..., 1]], axis=-1)
        return uv + np.asarray(self.offset)


def udim_tiles(path: str) -> dict[int, str]:
    """Tile number (1001, 1002, ... 1011 is the row above 1001) -> file, for a path with a UDIM token;
    the tiles found on disk."""
    for token in _UDIM_TOKENS:
        if token in path:
            head, tail = path.split(token, 1)
            pattern = re.compile(re.escape(os.path.basename(head)) + r"(1\d{3})" + re.escape(tail) + "$")
            found = {}
            for candidate in glob.glob(glob.escape(head) + "[0-9]" * 4 + glob.escape(tail)):
                match = pattern.search(os.path.basename(candidate))
                if match:
                    found[int(match.group(1))] = candidate
            return dict(sorted(found.items()))
    return {}


def tile_files(paths) -> list[str]:
    """``paths`` each once, in order, a UDIM path replaced by its tiles on disk (:func:`udim_tiles`)."""
    files = []
    for path in paths:
        has_token = any(token in path for token in _UDIM_TOKENS)
        files += list(udim_tiles(path).values()) if has_token else [path]
    return list(dict.fromkeys(files))


def udim_tile_of(uv: np.ndarray) -> np.ndarray:
    """(Q,) int64 UDIM tile of quads whose corner uv are ``uv`` (Q, 4, 2): ``1001 + u + 10 v`` at
    the quad's uv centre (a quad belongs to one tile; the tile's uv is its fractional part).

    >>> udim_tile_of(np.array([[[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]],
    ...                        [[1.2, 1.2], [1.8, 1.2], [1.8, 1.8], [1.2, 1.8]]])).tolist()
    [1001, 1012]
    """
    centre = np.floor(uv.mean(axis=1))
    return (1001 + centre[:, 0] + 10 * centre[:, 1]).astype(np.int64)

