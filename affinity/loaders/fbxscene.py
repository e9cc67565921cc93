"""An FBX scene read with ufbx as one :class:`~affinity.mesh.Mesh` (see :mod:`affinity.loaders.fbx`).

Runs where a crash costs one file (:mod:`affinity.loaders.isolated`). Topology and
per-corner values come from the file's own arrays (ufbx keeps the parsed
document, ``retain_dom``), copied out in one go where ufbx exposes a buffer
(elsewhere element by element): the ``PolygonVertexIndex`` as written (a negative index, bit-inverted,
ends each polygon), ``Vertices``, and each ``LayerElementUV``/``Normal``/``Color``
with its mapping (``ByPolygonVertex``, ``ByVertice``, ``ByPolygon``, ``AllSame``)
and reference (``Direct``, ``IndexToDirect``). Those are USD's interpolations under
other names, so :func:`affinity.loaders.usd.corner_index` turns them into corner
indices and checks them. An index outside its values stops ufbx (``ABORT_LOADING``:
by default it would clamp it, silently) and the file is unreadable. Node
transforms, materials and the scene's axes and units come from ufbx's scene.

The binding (0.0.5) crashes on a wrapper it hands out again after Python freed it,
and in the cycle collector: every object it gives is kept (:class:`_Kept`) until
the scene is read, with the collector off.
"""

from __future__ import annotations

import gc

import numpy as np

from ..errors import MeshError, SkippedFile
from ..mesh import Mesh
from .usd import _BadPrim, _concatenate, _Primvar, _transformed, colors_per_vertex, corner_index, world_normals

#: FBX layer mapping -> the USD interpolation that means the same.
INTERPOLATION = {"ByPolygonVertex": "faceVarying", "ByVertice": "vertex", "ByVertex": "vertex",
                 "ByPolygon": "uniform", "AllSame": "constant"}
#: The axis names of ufbx's CoordinateAxis values, sign dropped.
_AXIS = {"POSITIVE_X": "X", "NEGATIVE_X": "X", "POSITIVE_Y": "Y", "NEGATIVE_Y": "Y",
         "POSITIVE_Z": "Z", "NEGATIVE_Z": "Z"}


class _Kept:
    """A ufbx object whose every attribute, item and call result is kept alive until the scene is read.

    The binding keeps one Python wrapper per native object (element, list, DOM node) and hands the same
    wrapper out again after Python freed it, which crashes: so nothing it gives out is ever freed while
    its scene is open. Plain values (numbers, strings, named tuples) come back as they are.
    """

    __slots__ = ("kept", "native")

    def __init__(self, native, kept: list):
        self.native, self.kept = native, kept

    def _wrapped(self, value):
        if value is None or isinstance(value, (bool, int, float, str, bytes, tuple)):
            return value
        self.kept.append(value)
        return _Kept(value, self.kept)

    def __getattr__(self, name: str):
        return self._wrapped(getattr(self.native, name))

    def __getitem__(self, index: int):
        return self._wrapped(self.native[index])

    def __len__(self) -> int:
        return len(self.native)

    def __iter__(self):
        return (self._wrapped(self.native[i]) for i in range(len(self.native)))

    def __bool__(self) -> bool:
        return True


def read_fbx(path: str, uv_name: str | None = None) -> tuple[Mesh, dict[str, bytes]]:
    """Every visible mesh node of the FBX file at ``path`` as one mesh, a group per node (its node path),
    and the images the file embeds that its materials bind (name -> content,
    :func:`affinity.loaders.fbxmaterials.embedded_name`).

    ``uv_name`` picks the uv set by its FBX name (None: each mesh's first). Raises MeshError for a file
    ufbx cannot read or a mesh whose arrays disagree.
    """
    collecting = gc.isenabled()
    gc.disable()  # the binding's wrappers crash the cycle collector that walks them, even after the scene is freed
    try:
        read = _scene_contents(path, uv_name)
    finally:
        if collecting:
            gc.enable()
    parts, names, materials, notes = read["parts"], read["names"], read["materials"], read["notes"]
    if uv_name and all(part.texcoords is None for part in parts):
        notes.append(f"no mesh has the uv set {uv_name!r}: texture coordinates not checked")
    mesh = _concatenate(path, parts, names)
    mesh.face_material = np.concatenate([part.face_material for part in parts])
    mesh.material_names = materials
    mesh.material_maps = {name: found for name, found in read["maps"].items() if found}
    mesh.material_textures = {name: bases[0] for name, found in mesh.material_maps.items()
                              if (bases := [m.path for m in found if m.role == "base colour"])}  # as map_Kd
    mesh.prim_sources = read["sources"]
    mesh.up_axis, mesh.meters_per_unit = read["up_axis"], read["meters_per_unit"]
    mesh.notes = notes
    return mesh, read["embedded"]


def _scene_contents(path: str, uv_name: str | None) -> dict:
    """:func:`_read_scene` of the file at ``path``, the scene opened and freed here, so that no wrapper of
    the binding outlives this call."""
    import ufbx

    try:
        scene = ufbx.load_file(path, retain_dom=True, ignore_animation=True, skip_mesh_parts=True,
                               file_format=ufbx.FileFormat.FBX, load_external_files=False,
                               index_error_handling=ufbx.IndexErrorHandling.ABORT_LOADING)
    except ufbx.UfbxError as error:
        raise MeshError(path, 0, f"not a readable FBX file ({type(error).__name__}: {_reason(error)})") from None
    kept: list = []
    with scene:
        read = _read_scene(_Kept(scene, kept), path, uv_name)
        kept.clear()
    return read


def _read_scene(scene, path: str, uv_name: str | None) -> dict:
    """What :func:`read_fbx` keeps of an open scene, as plain values and arrays (no ufbx object outlives
    this call, so none outlives the scene): ``parts`` (a mesh per node, ``face_material`` into
    ``materials``), ``names`` (node paths), ``sources``, ``materials``, ``maps``, ``embedded``, ``notes``,
    ``up_axis``, ``meters_per_unit``."""
    from .fbxmaterials import material_maps

    nodes = [node for node in scene.nodes if node.mesh is not None]
    hidden = sum(not node.visible for node in nodes)
    nodes = [node for node in nodes if node.visible]
    if not nodes:  # an animation, a camera rig, or only hidden meshes: nothing to check, as a USD look layer
        raise SkippedFile(path, "no-mesh")
    notes = [f"{hidden} hidden mesh node{'s' * (hidden != 1)} skipped"] if hidden else []
    paths = node_paths(scene.root_node)
    # A mesh's place in the scene's list names its geometry (the binding's ids and names are not safe to
    # format twice); wrappers are one per native object, so identity finds it.
    geometry_of = {id(mesh.native): number for number, mesh in enumerate(scene.meshes)}
    parts, names, sources, materials, maps, embedded = [], [], [], [], {}, {}
    for node in nodes:
        node_path = paths.get(node.typed_id, f"/{node.name}")
        try:
            part, face_material = _read_node(node, uv_name)
        except _BadPrim as error:
            raise MeshError(path, 0, f"{node_path}: {error}") from None
        slots = [material.name for material in node.materials]
        for material in node.materials:
            if material.name not in maps:
                maps[material.name], images = material_maps(material, path, uv_name)
                embedded.update(images)
        materials += [name for name in dict.fromkeys(slots) if name not in materials]
        slot_material = np.asarray([materials.index(name) for name in slots] + [-1], dtype=np.int32)
        part.face_material = slot_material[np.where((face_material >= 0) & (face_material < len(slots)),
                                                    face_material, -1)]
        parts.append(part)
        names.append(node_path)
        sources.append((path, f"geometry {geometry_of.get(id(node.mesh.native), -1 - len(sources))}"))
    read = {"parts": parts, "names": names, "sources": sources, "materials": materials, "maps": maps,
            "embedded": embedded, "notes": notes, "up_axis": _AXIS.get(scene.settings.axes.up.name),
            "meters_per_unit": float(scene.settings.unit_meters)}
    return read


def node_paths(root) -> dict[int, str]:
    """Node ``typed_id`` -> its path ``/Parent/Child``: the names from below the scene's ``root`` down.
    Walked down through ``children`` (the binding's ``parent`` of a node is not safe to read)."""
    paths, stack = {}, [(child, "") for child in reversed(root.children)]
    while stack:
        node, above = stack.pop()
        path = f"{above}/{node.name}"
        paths[node.typed_id] = path
        stack += [(child, path) for child in reversed(node.children)]
    return paths


def _reason(error) -> str:
    return " ".join(str(error).split())[:300] or type(error).__name__


def _read_node(node, uv_name: str | None) -> tuple[Mesh, np.ndarray]:
    """One mesh node in world space (``geometry_to_world``), and the material slot of each face
    (F,) int32, -1 where none."""
    geometry = node.mesh.dom_node
    if geometry is None:
        raise _BadPrim("its geometry has no arrays")
    points = _finite("Vertices", _array(geometry, "Vertices", np.float64).reshape(-1, 3))
    written = _array(geometry, "PolygonVertexIndex", np.int64)
    sizes, corner_vertex = _polygons(written, len(points))
    topology = (len(points), sizes, corner_vertex)
    uv = _uv_layer(geometry, uv_name)
    normals = _layer(geometry, "LayerElementNormal", "Normals", "NormalsIndex", 3)
    color = _layer(geometry, "LayerElementColor", "Colors", "ColorIndex", 4)
    matrix = np.array(node.geometry_to_world, dtype=np.float64)  # (4, 3): columns of the 3x4 matrix
    linear, offset = matrix[:3], matrix[3]  # rows: p' = p linear + offset (row vectors)
    positions = _transformed(points, linear) + offset
    colors = None
    if color is not None:
        values = np.clip(color.values[:, :3], 0.0, 1.0)
        positions, corner_vertex, colors = colors_per_vertex(positions, corner_vertex,
                                                             corner_index(color, *topology), values)
    part = Mesh(
        path=node.name, positions=positions,
        face_start=np.concatenate(([0], np.cumsum(sizes))), corner_vertex=corner_vertex,
        face_line=np.zeros(len(sizes), dtype=np.int64),
        texcoords=None if uv is None else uv.values,
        corner_texcoord=None if uv is None else corner_index(uv, *topology),
        normals=None if normals is None else world_normals(normals.values, linear),
        corner_normal=None if normals is None else corner_index(normals, *topology),
        colors=colors,
    )
    return part, _face_materials(geometry, sizes)


def _polygons(written: np.ndarray, n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """``PolygonVertexIndex`` (C,) as face sizes (F,) int64 and corner points (C,) int64."""
    ends = np.flatnonzero(written < 0)
    if len(written) and (not len(ends) or ends[-1] != len(written) - 1):
        raise _BadPrim("PolygonVertexIndex does not end its last polygon")
    sizes = np.diff(np.concatenate(([-1], ends)))
    if len(sizes) and sizes.min() < 3:
        face = int(np.argmax(sizes < 3))
        raise _BadPrim(f"polygon {face} has {sizes[face]} corners (at least 3 needed)")
    corner_vertex = np.where(written < 0, ~written, written)
    if len(corner_vertex) and corner_vertex.max() >= n_points:
        raise _BadPrim(f"PolygonVertexIndex has an entry outside the {n_points} vertices")
    return sizes, corner_vertex


def _children(geometry, name: str) -> list:
    return [child for child in geometry.children if child.name == name]


def _find(node: _Kept, name: str) -> _Kept | None:
    """The DOM child ``name`` of ``node`` (``ufbx.dom_find``), kept; None when there is none."""
    import ufbx

    return node._wrapped(ufbx.dom_find(node.native, name))


def _dom_list(node: _Kept, function: str) -> _Kept:
    """``ufbx.<function>(node)``, the array of a DOM node, kept."""
    import ufbx

    return node._wrapped(getattr(ufbx, function)(node.native))


def _text(node, name: str) -> str:
    """The string value of the DOM child ``name`` of ``node``; "" when it has none."""
    found = _find(node, name)
    if found is None or not found.values or found.values[0].type.name != "STRING":
        return ""
    return found.values[0].value_str


def _array(node, name: str, dtype) -> np.ndarray:
    """The array child ``name`` of DOM ``node`` as (n,) ``dtype``, copied out of the scene."""
    found = _find(node, name)
    if found is None or not found.values:
        raise _BadPrim(f"it has no {name}")
    kind = found.values[0].type.name
    if kind in ("ARRAY_F64", "ARRAY_I32"):  # a buffer: one copy out of the scene
        items = _dom_list(found, "dom_as_real_list" if kind == "ARRAY_F64" else "dom_as_int32_list").native
        return np.array(memoryview(items), dtype=dtype).reshape(-1)
    if kind in ("ARRAY_F32", "ARRAY_I64"):  # no buffer from the binding: element by element
        items = _dom_list(found, "dom_as_float_list" if kind == "ARRAY_F32" else "dom_as_int64_list").native
        return np.fromiter(items, dtype=np.float64 if kind == "ARRAY_F32" else np.int64,
                           count=len(items)).astype(dtype)
    raise _BadPrim(f"{name} is not an array of numbers")


def _finite(name: str, values: np.ndarray) -> np.ndarray:
    if not np.isfinite(values).all():
        raise _BadPrim(f"{name} has NaN or Inf values")
    return values


def _layer_values(element, kind: str, values: str, indices: str, width: int) -> _Primvar | None:
    """One layer element as a :class:`~affinity.loaders.usd._Primvar`; None for a mapping not kept
    (``ByEdge``)."""
    mapping = _text(element, "MappingInformationType")
    if mapping not in INTERPOLATION:
        return None
    data = _array(element, values, np.float64)
    if len(data) % width:
        raise _BadPrim(f"{kind} {values} has {len(data)} numbers, not a multiple of {width}")
    reference = _text(element, "ReferenceInformationType")
    index = None
    if reference in ("IndexToDirect", "Index") and _find(element, indices) is not None:
        index = _array(element, indices, np.int64)
    name = f"{kind} {values} ({mapping})"  # corner_index's messages speak USD: the FBX mapping beside it
    return _Primvar(name, _finite(name, data.reshape(-1, width)), INTERPOLATION[mapping], index)


def _layer(geometry, kind: str, values: str, indices: str, width: int) -> _Primvar | None:
    """The first ``kind`` layer element of a geometry, or None."""
    elements = _children(geometry, kind)
    return _layer_values(elements[0], kind, values, indices, width) if elements else None


def _uv_layer(geometry, name: str | None) -> _Primvar | None:
    """The uv set named ``name`` (its ``Name``), else the first one; None when there is none."""
    elements = _children(geometry, "LayerElementUV")
    if name is not None:
        elements = [element for element in elements if _text(element, "Name") == name]
    return _layer_values(elements[0], "LayerElementUV", "UV", "UVIndex", 2) if elements else None


def _face_materials(geometry, sizes: np.ndarray) -> np.ndarray:
    """(F,) int32 material slot of each face from ``LayerElementMaterial`` (``AllSame`` or ``ByPolygon``);
    0 for every face without one (the node's first material), -1 past the slots the layer names."""
    elements = _children(geometry, "LayerElementMaterial")
    if not elements or _find(elements[0], "Materials") is None:
        return np.zeros(len(sizes), dtype=np.int32)
    slots = _array(elements[0], "Materials", np.int64)
    if _text(elements[0], "MappingInformationType") == "ByPolygon" and len(slots) == len(sizes):
        return slots.astype(np.int32)
    return np.full(len(sizes), slots[0] if len(slots) else 0, dtype=np.int32)
