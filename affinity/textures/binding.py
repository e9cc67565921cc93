"""Which texture file each quad reads, and the texel grid of its uv.

A face reads the texture maps of its material (``Mesh.material_maps``); faces
without a material read those of the mesh's first material that has maps. A UDIM map is one file per
tile, the tile chosen by the quad's uv centre (:func:`affinity.loaders.texturemaps.udim_tile_of`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..loaders.imagesize import ImageHeader
from ..loaders.texturemaps import ROLES, TextureMap, udim_tile_of, udim_tiles
from .decode import header_or_reason


@dataclass(frozen=True, eq=False)
class BoundTexture:
    """One texture file and the faces that read it.

    Attributes
    ----------
    map : the material's texture map
    path : the file (for a UDIM map, the tile's; it may be missing)
    faces : (n,) int64 face indices in file order
    tile : the UDIM tile, or None
    """

    map: TextureMap
    path: str
    faces: np.ndarray
    tile: int | None = None

    @property
    def label(self) -> str:
        """How a message names it: ``base colour spot_texture.png (map_Kd)``."""
        name = os.path.basename(self.path) if self.tile is not None else self.map.name
        return f"{self.map.role} {name} ({self.map.source})"

    def tile_uv(self, uv: np.ndarray) -> np.ndarray:
        """(Q, 4, 2) float64 where quads with mesh uv ``uv`` (Q, 4, 2) read this file: after the map's
        scale and offset, and for a UDIM tile moved into the unit square."""
        uv = self.map.texture_uv(uv)
        if self.tile is None:
            return uv
        return uv - np.floor(uv.mean(axis=1, keepdims=True))


def material_maps(mesh) -> dict[str, list[TextureMap]]:
    """``mesh.material_maps``; for a mesh built with ``material_textures`` only (a Blender object, a test),
    those as base colour maps."""
    if mesh.material_maps or not mesh.material_textures:
        return mesh.material_maps
    return {material: [TextureMap(role="base colour", path=path, name=os.path.basename(path), source="map_Kd")]
            for material, path in mesh.material_textures.items()}


def _material_of_faces(mesh, maps: dict) -> tuple[list[str], np.ndarray]:
    """The materials with maps and (F,) int64 the index of each face's into them (-1: none)."""
    names = list(maps)
    if not names:
        return names, np.full(mesh.n_faces, -1, dtype=np.int64)
    lookup = np.array([names.index(n) if n in maps else -1 for n in mesh.material_names] + [-1])
    fallback = next((names.index(n) for n in mesh.material_names if n in maps), 0)
    lookup[-1] = fallback  # face_material -1 (no usemtl) indexes the last entry
    return names, lookup[mesh.face_material]


def quad_uv(mesh, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The uv of quads ``faces`` (n,) at their four corners, (n, 4, 2) float64, and (n,) bool which have
    uv at every corner (the others' rows are NaN)."""
    corners = mesh.face_start[faces][:, None] + np.arange(4)
    index = mesh.corner_texcoord[corners]
    uv = mesh.texcoords[np.maximum(index, 0)].astype(np.float64)
    complete = (index >= 0).all(axis=1) & np.isfinite(uv).all(axis=(1, 2))
    uv[~complete] = np.nan
    return uv, complete


def bound_textures(mesh, faces: np.ndarray) -> list[BoundTexture]:
    """Every texture file the quads ``faces`` (n,) int64 read, each with the faces that read it; in
    material order, within a material by role (:data:`ROLES`), UDIM tiles in tile order."""
    maps = material_maps(mesh)
    names, material = _material_of_faces(mesh, maps)
    if not names or mesh.texcoords is None:
        return []
    material = material[faces]
    bound = []
    for index, name in enumerate(names):
        own = faces[material == index]
        if not len(own):
            continue
        for texture_map in sorted(maps[name], key=lambda m: ROLES.index(m.role)):
            if not texture_map.udim:
                bound.append(BoundTexture(texture_map, texture_map.path, own))
                continue
            uv, complete = quad_uv(mesh, own)
            tiles = np.zeros(len(own), dtype=np.int64)
            tiles[complete] = udim_tile_of(texture_map.texture_uv(uv[complete]))
            files = udim_tiles(texture_map.path)
            for tile in np.unique(tiles[complete]).tolist():
                path = files.get(tile, _tile_path(texture_map.path, tile))
                bound.append(BoundTexture(texture_map, path, own[complete & (tiles == tile)], tile))
    return bound


def _tile_path(path: str, tile: int) -> str:
    """The file a UDIM path names for ``tile`` (one that is not on disk)."""
    for token in ("<UDIM>", "<udim>", "%(UDIM)d"):
        path = path.replace(token, str(tile))
    return path


@dataclass
class TexelGrid:
    """The texel grid Q101 counts texels in, per quad.

    Attributes
    ----------
    sizes : (2,) or (F, 2) float64, (width, height) of every face's texture (one row for all, or per face)
    assumed : (F,) bool, faces counted at the ``texture-size`` setting (no readable header)
    """

    sizes: np.ndarray
    assumed: np.ndarray

    def of(self, faces: np.ndarray) -> np.ndarray:
        """(2,) or (n, 2) float64: the sizes for ``faces`` (n,) int64."""
        return self.sizes if self.sizes.ndim == 1 else self.sizes[faces]


def texel_grid(mesh, texture_size: int, faces: np.ndarray | None = None) -> TexelGrid:
    """Each face's texel grid: the size its material's texture header gives (the base colour map's,
    else the first role's that has a readable header; a UDIM tile's own), else ``texture_size``
    (design.md, "Texture size for the texel unit"). ``faces`` limits the work to those quads (default:
    every quad of the mesh); other faces read ``texture_size``."""
    assumed_size = np.array([texture_size, texture_size], dtype=np.float64)
    assumed = np.ones(mesh.n_faces, dtype=bool)
    if not mesh.material_maps and not mesh.material_textures:
        return TexelGrid(assumed_size, assumed)
    faces = np.flatnonzero(mesh.face_sizes == 4) if faces is None else faces
    sizes = np.broadcast_to(assumed_size, (mesh.n_faces, 2)).copy()
    headers: dict[str, ImageHeader | None] = {}
    for bound in reversed(bound_textures(mesh, faces)):  # the base colour map, listed first, is written last
        if bound.path not in headers:
            headers[bound.path] = header_or_reason(bound.path)[0]
        if headers[bound.path] is not None:
            sizes[bound.faces] = headers[bound.path].size
            assumed[bound.faces] = False
    first = sizes[faces[0]] if len(faces) else assumed_size
    one_size = not len(faces) or bool((sizes[faces] == first).all())
    return TexelGrid(first.copy() if one_size else sizes, assumed)
