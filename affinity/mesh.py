"""The polygon mesh model shared by every loader, measure and rule.

Faces are kept exactly as the file wrote them: quads stay quads, triangles and
n-gons are kept and counted, nothing is triangulated. Faces live in compressed
("CSR") form: face ``f`` owns corners ``face_start[f]:face_start[f + 1]`` of the
per-corner arrays. Texture coordinates and normals are indexed per corner,
separately from positions (OBJ ``v/vt/vn`` style), so UV seams and mirrored UVs
survive. Vertex colours are per position vertex, as OBJ and PLY store them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .attributes import ATTRIBUTES


@dataclass(eq=False)
class Mesh:
    """A polygon mesh with per-corner attributes.

    Attributes
    ----------
    path : str
        The file the mesh was read from (as given).
    positions : (V, 3) float64
    face_start : (F + 1,) int64
        Offsets of each face's corners into the corner arrays; ``face_start[0] == 0``.
    corner_vertex : (C,) int64
        0-based index into ``positions`` for every corner.
    face_line : (F,) int32 or int64
        1-based source line of every face; 0 where the format has no lines (binary PLY, USD).
    texcoords : (T, 2) float64 or None
    corner_texcoord : (C,) int64 or None
        Index into ``texcoords`` per corner, -1 for a corner without one.
    normals : (N, 3) float64 or None
    corner_normal : (C,) int64 or None
        Index into ``normals`` per corner, -1 for a corner without one.
    colors : (V, 3) float64 or None
        Per-vertex RGB in [0, 1] (reached through ``corner_vertex``); NaN rows for
        vertices without a colour (USD prims without ``displayColor``).
    group_names : list of str
        Group/object names; ``face_group`` indexes into it. In a USD stage, one
        group per mesh prim, named by its prim path.
    face_group : (F,) int8, int16 or int32
        The narrowest that holds the index (an OBJ file's faces; other loaders give int32).
    material_names : list of str
    face_material : (F,) int8, int16 or int32
        Index into ``material_names``, -1 for faces without ``usemtl``.
    material_textures : dict of str to str
        Material name to its ``map_Kd`` path (resolved against the .mtl file's folder).
    material_maps : dict of str to list of affinity.loaders.texturemaps.TextureMap
        Material name to every texture it reads through the uv, by role (base colour,
        normal, height, scalar maps).
    resources : list of affinity.loaders.resources.Resource
        The files the mesh file references (material libraries, texture maps by
        role, USD layers), in file order, as its loader read them.
    prim_face_start : (P + 1,) int64 or None
        USD and FBX only: the faces of mesh prim (FBX: mesh node) ``p`` (group ``p``) are
        ``prim_face_start[p]:prim_face_start[p + 1]``. None for other formats.
    prim_sources : list of (str, str) or None, one per prim
        USD only: the layer and the prim path in it where each mesh prim's points and
        topology are authored (None for a prim whose three come from different places):
        prims that reference one geometry layer share a source. FBX: the file and the geometry each node
        instances, so nodes sharing one geometry share a source.
    up_axis : str or None
        USD and FBX only: the stage's ``upAxis`` (``"Y"`` or ``"Z"``), the FBX scene's up axis.
    meters_per_unit : float or None
        USD and FBX only: the stage's ``metersPerUnit``, the FBX scene's unit.
    notes : list of str
        What the loader read but did not represent, for the user (e.g. USD
        PointInstancer copies that were not expanded).
    subdivision : list of affinity.subdivision.Scheme or None
        USD only: per prim (group), how its faces subdivide (``subdivisionScheme``, ``interpolateBoundary``,
        ``faceVaryingLinearInterpolation``, creases, corners, holes; vertex and face indices into this mesh).
        None where the format names no scheme (OBJ, PLY, OFF).
    position_epsilon : float
        The machine epsilon of the positions as stored in the file (float64's unless the loader knows better:
        a USD ``point3f[]`` is float32): what counts as rounding in the shape rules
        (:attr:`affinity.geometry.PlanarQuads.rounding`).
    """

    path: str
    positions: np.ndarray
    face_start: np.ndarray
    corner_vertex: np.ndarray
    face_line: np.ndarray
    texcoords: np.ndarray | None = None
    corner_texcoord: np.ndarray | None = None
    normals: np.ndarray | None = None
    corner_normal: np.ndarray | None = None
    colors: np.ndarray | None = None
    group_names: list[str] = field(default_factory=lambda: [""])
    face_group: np.ndarray | None = None
    material_names: list[str] = field(default_factory=list)
    face_material: np.ndarray | None = None
    material_textures: dict[str, str] = field(default_factory=dict)
    material_maps: dict[str, list] = field(default_factory=dict)
    resources: list = field(default_factory=list)
    prim_face_start: np.ndarray | None = None
    prim_sources: list | None = None
    up_axis: str | None = None
    meters_per_unit: float | None = None
    notes: list[str] = field(default_factory=list)
    subdivision: list | None = None
    position_epsilon: float = float(np.finfo(np.float64).eps)

    def __post_init__(self):
        if self.face_group is None:
            self.face_group = np.zeros(self.n_faces, dtype=np.int32)
        if self.face_material is None:
            self.face_material = np.full(self.n_faces, -1, dtype=np.int32)

    @property
    def n_faces(self) -> int:
        return len(self.face_start) - 1

    @property
    def face_sizes(self) -> np.ndarray:
        """(F,) int64 number of corners of every face."""
        return np.diff(self.face_start)

    def counts(self) -> dict[str, int]:
        """Faces by size as read from the file: ``faces``, ``quads``, ``triangles``, ``ngons``."""
        sizes = self.face_sizes
        triangles = int(np.count_nonzero(sizes == 3))
        quads = int(np.count_nonzero(sizes == 4))
        return {
            "faces": self.n_faces,
            "quads": quads,
            "triangles": triangles,
            "ngons": self.n_faces - quads - triangles,
        }

    def faces_of_size(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Faces with exactly ``k`` corners.

        Returns
        -------
        faces : (n,) int64
            Their indices in file order.
        corners : (n, k) int64
            Their corner indices (into ``corner_vertex`` and the other corner arrays).
        """
        faces = np.flatnonzero(self.face_sizes == k)
        corners = self.face_start[faces, None] + np.arange(k)
        return faces, corners

    def corner_attribute(self, name: str, corners: np.ndarray) -> np.ndarray | None:
        """Gather an attribute at the given corners.

        Parameters
        ----------
        name : {"positions", "texcoords", "normals", "colors"}
        corners : (n, k) int64 corner indices, e.g. from :meth:`faces_of_size`.

        Returns
        -------
        (n, k, D) float64, NaN for corners that lack the attribute, or None when
        the mesh has no such attribute at all.
        """
        values = getattr(self, name)
        if name == "positions" or ATTRIBUTES[name].per_vertex:
            return None if values is None else values[self.corner_vertex[corners]]
        index = getattr(self, ATTRIBUTES[name].corner_index)
        if values is None or index is None or len(values) == 0:
            return None
        picked = index[corners]
        out = values[np.maximum(picked, 0)]
        out[picked < 0] = np.nan
        return out

    def validate(self) -> None:
        """Raise ValueError naming every invariant of the model this mesh breaks.

        What every loader guarantees and every measure relies on: array shapes
        and integer types, ``face_start`` rising from 0 by at least 3 corners a
        face to the number of corners, every index inside what it indexes (-1
        for an absent texcoord or normal), finite positions, texture
        coordinates and normals, colours in [0, 1] (NaN: none), and the
        group, material and prim tables covering every face.
        """
        problems = []

        def require(condition, what: str) -> None:
            if not condition:
                problems.append(what)

        def shaped(name: str, array, width: int | None, kind: str) -> bool:
            ok = isinstance(array, np.ndarray) and array.dtype.kind in kind and (
                array.ndim == 1 if width is None else (array.ndim == 2 and array.shape[1] == width))
            require(ok, f"{name} is not a {'(n,)' if width is None else f'(n, {width})'} {kind} array")
            return ok

        def indexes(name: str, index, total: int, low: int) -> None:
            if shaped(name, index, None, "iu"):
                require(len(index) == n_corners, f"{name} has {len(index)} entries for {n_corners} corners")
                require(len(index) == 0 or (index.min() >= low and index.max() < total),
                        f"{name} has an entry outside [{low}, {total})")

        n_vertices = len(self.positions) if shaped("positions", self.positions, 3, "f") else 0
        require(np.isfinite(self.positions).all(), "positions are not all finite")
        n_corners = len(self.corner_vertex) if shaped("corner_vertex", self.corner_vertex, None, "iu") else 0
        if shaped("face_start", self.face_start, None, "iu"):
            require(len(self.face_start) >= 1 and self.face_start[0] == 0, "face_start does not start at 0")
            require((np.diff(self.face_start) >= 3).all(), "a face has fewer than 3 corners")
            require(self.face_start[-1:].tolist() in ([n_corners], []), "face_start does not end at the corner count")
        indexes("corner_vertex", self.corner_vertex, n_vertices, 0)
        n_faces = max(self.n_faces, 0)
        for name, table in (("face_line", self.face_line), ("face_group", self.face_group),
                            ("face_material", self.face_material)):
            if shaped(name, table, None, "iu"):
                require(len(table) == n_faces, f"{name} has {len(table)} entries for {n_faces} faces")
        require(len(self.face_line) == 0 or self.face_line.min() >= 0, "face_line has a negative line")
        require(len(self.face_group) == 0 or (self.face_group.min() >= 0
                                              and self.face_group.max() < len(self.group_names)),
                "face_group has an entry outside group_names")
        require(len(self.face_material) == 0 or (self.face_material.min() >= -1
                                                 and self.face_material.max() < len(self.material_names)),
                "face_material has an entry outside material_names")
        for values, index, width in ((a.field, a.corner_index, a.width) for a in ATTRIBUTES.values()
                                     if not a.per_vertex):
            array = getattr(self, values)
            require((array is None) == (getattr(self, index) is None), f"{values} and {index} are not both given")
            if array is not None and shaped(values, array, width, "f"):
                require(np.isfinite(array).all(), f"{values} are not all finite")
                if getattr(self, index) is not None:
                    indexes(index, getattr(self, index), len(array), -1)
        if self.colors is not None and shaped("colors", self.colors, ATTRIBUTES["colors"].width, "f"):
            require(len(self.colors) == n_vertices, f"colors has {len(self.colors)} rows for {n_vertices} vertices")
            inside = (self.colors >= 0) & (self.colors <= 1)
            require((inside | np.isnan(self.colors)).all(), "a colour is outside [0, 1]")
        if self.prim_face_start is not None and shaped("prim_face_start", self.prim_face_start, None, "iu"):
            starts = self.prim_face_start
            require(len(starts) == len(self.group_names) + 1 and starts[0] == 0 and starts[-1] == n_faces
                    and (np.diff(starts) >= 0).all(), "prim_face_start does not split the faces into the prims")
        if problems:
            raise ValueError(f"{self.path}: inconsistent mesh: " + "; ".join(problems))



def mesh_from_polygons(
    path: str,
    positions: np.ndarray,
    faces: np.ndarray,
    texcoords: np.ndarray | None = None,
    normals: np.ndarray | None = None,
    colors: np.ndarray | None = None,
) -> Mesh:
    """Build an in-memory mesh whose faces all have the same size, attributes per vertex.

    Parameters
    ----------
    path : str, a name for messages (the mesh has no file, so ``face_line`` is 0)
    positions : (V, 3) float
    faces : (F, k) int, 0-based vertex indices
    texcoords : (V, 2) float or None, indexed like positions
    normals : (V, 3) float or None, indexed like positions
    colors : (V, 3) float in [0, 1] or None
    """
    faces = np.asarray(faces, dtype=np.int64)
    n_faces, k = faces.shape
    corners = faces.reshape(-1)

    def per_vertex(values, width):
        return None if values is None else np.asarray(values, dtype=np.float64).reshape(-1, width)

    return Mesh(
        path=path,
        positions=per_vertex(positions, 3),
        face_start=np.arange(0, n_faces * k + 1, k, dtype=np.int64),
        corner_vertex=corners,
        face_line=np.zeros(n_faces, dtype=np.int64),
        texcoords=per_vertex(texcoords, 2),
        corner_texcoord=None if texcoords is None else corners.copy(),
        normals=per_vertex(normals, 3),
        corner_normal=None if normals is None else corners.copy(),
        colors=per_vertex(colors, 3),
    )
