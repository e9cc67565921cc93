"""Q101's visible reading for a mesh: every flagged quad read through every texture it binds.

:func:`visible_reading` takes the quads Q101 flags with their shift (texels), finds
the textures each reads (:func:`affinity.textures.binding.bound_textures`), decodes
each once (:func:`affinity.textures.decode.decode`), measures C per texture
(:func:`affinity.textures.visible.visible_values`) and keeps, per quad, the worst
role: the higher level, then the larger C relative to ``visible-error``. A texture
that cannot be decoded leaves its quads on the texel reading, with a note.
"""

from __future__ import annotations

import threading

import numpy as np

from ..findings import VisibleColumns
from ..geometry import plane_coordinates
from ..rules import LEVELS
from .binding import bound_textures, quad_uv
from .decode import TextureUnusable, decode, why_not_decoded
from .visible import BOTH_DIAGONALS, DIAGONAL_02, DIAGONAL_13, EXACT, visible_values
from .wrapping import WrappedTexture

#: The unit of C by what the texture holds.
UNITS = {False: "1/255", True: "degrees"}


def split_diagonals(mesh, faces: np.ndarray, diagonal: str) -> np.ndarray:
    """(n,) int8 diagonal codes of quads ``faces`` for the ``diagonal`` setting; ``shortest`` takes the
    diagonal shorter in 3-D (design.md)."""
    if diagonal != "shortest":
        code = {"02": DIAGONAL_02, "13": DIAGONAL_13, "both": BOTH_DIAGONALS}[diagonal]
        return np.full(len(faces), code, dtype=np.int8)
    p = mesh.positions[mesh.corner_vertex[mesh.face_start[faces][:, None] + np.arange(4)]]
    d02, d13 = np.linalg.norm(p[:, 2] - p[:, 0], axis=1), np.linalg.norm(p[:, 3] - p[:, 1], axis=1)
    return np.where(d02 <= d13, DIAGONAL_02, DIAGONAL_13).astype(np.int8)


def prepare_textures(mesh) -> threading.Thread | None:
    """Start decoding, in a background thread, every texture the mesh's quads read that the budget lets
    decode (:class:`~affinity.textures.decode.DecodedTexture`; its pyramids are reduced later, where the
    flagged quads' queries reach), so that the work overlaps the lint's; join the thread before reading C.
    None when there is nothing to decode."""
    quads = np.flatnonzero(mesh.face_sizes == 4)
    paths = list(dict.fromkeys(bound.path for bound in bound_textures(mesh, quads)))
    paths = [path for path in paths if why_not_decoded(path) is None]
    if not paths:
        return None

    def warm() -> None:
        for path in paths:
            try:
                decode(path)
            except TextureUnusable:
                continue  # the reading says why

    thread = threading.Thread(target=warm, name="affinity-textures", daemon=True)
    thread.start()
    return thread


def visible_reading(mesh, settings, faces: np.ndarray, shifts: np.ndarray) -> tuple[VisibleColumns, dict] | None:
    """C for the quads ``faces`` (n,) int64, in file order, that Q101 flags with shifts ``shifts`` (n,)
    texels: the columns (``values`` C, NaN where no texture was read) and the notes, row -> why a texture
    was not read (on the first quad that reads it); None when the mesh binds no texture to them."""
    textures = bound_textures(mesh, faces)
    if not textures:
        return None
    n = len(faces)
    limits = settings.visible_limits
    columns = VisibleColumns(values=np.full(n, np.nan), shifts=np.array(shifts, dtype=np.float64),
                             bounds=np.full(n, EXACT, dtype=np.int8), picks=np.full(n, -1, dtype=np.int32),
                             textures=[], roles=[], units=[], limits=(limits.error, limits.warning, limits.min_shift))
    notes: dict[int, str] = {}
    rank = np.full(n, -1.0)  # the worse role: level first, then C relative to visible-error
    corners = mesh.face_start[faces][:, None] + np.arange(4)
    xy = plane_coordinates(mesh.positions[mesh.corner_vertex[corners]].astype(np.float64))
    uv, _ = quad_uv(mesh, faces)
    diagonals = split_diagonals(mesh, faces, settings.diagonal)
    for bound in textures:
        rows = np.searchsorted(faces, bound.faces)
        try:
            texture = decode(bound.path)
        except TextureUnusable as err:
            size = "" if err.header is None else f"; texels of its {err.header.width}x{err.header.height} header"
            notes.setdefault(int(rows[0]), f"{bound.label}: {err}{size}")
            continue
        if bound.map.wrap != ("repeat", "repeat"):
            texture = WrappedTexture(texture, bound.map.wrap)
        normal_map = bound.map.role == "normal" or (bound.map.role == "height" and texture.looks_like_normal_map)
        values, bounds = visible_values(texture, xy[rows], bound.tile_uv(uv[rows]), diagonals[rows], normal_map,
                                        limits)
        levels = limits.levels(values, shifts[rows])
        severity = (len(LEVELS) - np.select([levels == level for level in LEVELS], range(len(LEVELS)))
                    + np.minimum(values / max(limits.error, 1e-12), 0.999))
        worse = severity > rank[rows]
        picked = rows[worse]
        rank[picked] = severity[worse]
        columns.values[picked], columns.bounds[picked] = values[worse], bounds[worse]
        columns.picks[picked] = len(columns.textures)
        columns.textures.append(bound.path)
        columns.roles.append("normal (bump)" if normal_map and bound.map.role == "height" else bound.map.role)
        columns.units.append(UNITS[normal_map])
    columns.shifts[~np.isfinite(columns.values)] = np.nan
    return columns, notes
