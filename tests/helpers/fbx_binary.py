"""A small binary FBX (7.4) writer for tests and benchmarks: one or more mesh nodes, arrays uncompressed.

Written from the format as the Blender exporter's ``encode_bin.py`` and ufbx read it: a 27-byte header
(``Kaydara FBX Binary  \\0\\x1a\\0`` and the version), then node records, each ``end offset (u32),
property count (u32), property bytes (u32), name length (u8), name, properties, children``, a list of
children closed by a 13-byte null record; array properties are ``count (u32), encoding (u32: 0 raw,
1 zlib), bytes (u32), data``. Enough for ufbx to read meshes with uv sets, normals, colours and materials'
face slots, so the loader's tests can write what Blender cannot (a hostile index, a mapping Blender never
writes) and the benchmark can write a million quads in a second. Not product code: the product reads FBX
only.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass, field

import numpy as np

HEADER = b"Kaydara FBX Binary  \x00\x1a\x00" + struct.pack("<I", 7400)
_NULL_RECORD = b"\x00" * 13
_ARRAY_CODES = {np.dtype(np.float64): b"d", np.dtype(np.int32): b"i", np.dtype(np.float32): b"f",
                np.dtype(np.int64): b"l"}


@dataclass
class Node:
    """An FBX node: ``name``, its properties (int, float, str, bytes or a NumPy array) and children."""

    name: str
    properties: list = field(default_factory=list)
    children: list[Node] = field(default_factory=list)


def _property(value, compress: bool = False) -> bytes:
    if isinstance(value, np.ndarray):
        data = np.ascontiguousarray(value.ravel())
        raw = zlib.compress(data.tobytes(), 1) if compress else data.tobytes()
        return _ARRAY_CODES[data.dtype] + struct.pack("<III", len(data), int(compress), len(raw)) + raw
    if isinstance(value, bool):
        return b"C" + struct.pack("<?", value)
    if isinstance(value, int):
        return (b"I" + struct.pack("<i", value)) if -2**31 <= value < 2**31 else (b"L" + struct.pack("<q", value))
    if isinstance(value, float):
        return b"D" + struct.pack("<d", value)
    raw = value.encode() if isinstance(value, str) else bytes(value)
    return (b"S" if isinstance(value, str) else b"R") + struct.pack("<I", len(raw)) + raw


def _record(node: Node, offset: int, compress: bool) -> bytes:
    """The bytes of ``node`` written at file offset ``offset``, arrays zlib-compressed with ``compress``."""
    properties = b"".join(_property(p, compress) for p in node.properties)
    name = node.name.encode()
    head_size = 13 + len(name) + len(properties)
    children = b""
    for child in node.children:
        children += _record(child, offset + head_size + len(children), compress)
    if node.children or not node.properties:
        children += _NULL_RECORD
    end = offset + head_size + len(children)
    return struct.pack("<IIIB", end, len(node.properties), len(properties), len(name)) + name + properties + \
        children


def document(nodes: list[Node], compress: bool = False) -> bytes:
    """A whole binary FBX file of the top-level ``nodes``; ``compress``: arrays zlib-compressed, as DCC tools
    write them."""
    body = b""
    for node in nodes:
        body += _record(node, len(HEADER) + len(body), compress)
    return HEADER + body + _NULL_RECORD + b"\x00" * 16


@dataclass
class MeshNode:
    """One mesh to write: polygons ``face_start`` (F + 1,) and ``corner_vertex`` (C,), ``positions`` (V, 3);
    layers as ``(name, mapping, reference, values (n, k), indices or None)``; ``materials`` the names of the
    node's material slots and ``face_slots`` (F,) int32 the slot of each face (or None); ``parent`` the index
    of the mesh node above it (None: the scene's root) and ``translation`` its local translation;
    ``geometry`` the index of the mesh whose geometry it uses (None: its own); ``vertex_dtype`` and
    ``index_dtype`` the array types of ``Vertices`` and ``PolygonVertexIndex`` (float32 and int64 are legal
    too)."""

    name: str
    positions: np.ndarray
    face_start: np.ndarray
    corner_vertex: np.ndarray
    uv: list = field(default_factory=list)
    normals: tuple | None = None
    colors: tuple | None = None
    materials: list[str] = field(default_factory=list)
    face_slots: np.ndarray | None = None
    translation: tuple = (0.0, 0.0, 0.0)
    geometry: int | None = None
    vertex_dtype: type = np.float64
    index_dtype: type = np.int32


def _layer(kind: str, values_name: str, index_name: str, layer: tuple, number: int) -> Node:
    name, mapping, reference, values, indices = layer
    children = [Node("Version", [101]), Node("Name", [name]), Node("MappingInformationType", [mapping]),
                Node("ReferenceInformationType", [reference]),
                Node(values_name, [np.asarray(values, dtype=np.float64)])]
    if indices is not None:
        children.append(Node(index_name, [np.asarray(indices, dtype=np.int32)]))
    return Node(kind, [number], children)


def polygon_vertex_index(face_start: np.ndarray, corner_vertex: np.ndarray) -> np.ndarray:
    """(C,) int32 FBX ``PolygonVertexIndex``: the corners' vertices, each polygon's last bit-inverted."""
    written = np.asarray(corner_vertex, dtype=np.int32).copy()
    last = np.asarray(face_start[1:]) - 1
    written[last] = ~written[last]
    return written


def _geometry(mesh: MeshNode, object_id: int) -> Node:
    children = [Node("GeometryVersion", [124]),
                Node("Vertices", [np.asarray(mesh.positions, dtype=mesh.vertex_dtype)]),
                Node("PolygonVertexIndex", [polygon_vertex_index(mesh.face_start, mesh.corner_vertex)
                                            .astype(mesh.index_dtype)])]
    elements = []
    if mesh.normals is not None:
        children.append(_layer("LayerElementNormal", "Normals", "NormalsIndex", mesh.normals, 0))
        elements.append(("LayerElementNormal", 0))
    for number, layer in enumerate(mesh.uv):
        children.append(_layer("LayerElementUV", "UV", "UVIndex", layer, number))
        elements.append(("LayerElementUV", number))
    if mesh.colors is not None:
        children.append(_layer("LayerElementColor", "Colors", "ColorIndex", mesh.colors, 0))
        elements.append(("LayerElementColor", 0))
    if mesh.face_slots is not None:
        children.append(Node("LayerElementMaterial", [0], [
            Node("Version", [101]), Node("Name", [""]), Node("MappingInformationType", ["ByPolygon"]),
            Node("ReferenceInformationType", ["IndexToDirect"]),
            Node("Materials", [np.asarray(mesh.face_slots, dtype=np.int32)])]))
        elements.append(("LayerElementMaterial", 0))
    children.append(Node("Layer", [0], [Node("Version", [100])] + [
        Node("LayerElement", [], [Node("Type", [kind]), Node("TypedIndex", [0])]) for kind, number in elements
        if number == 0]))
    return Node("Geometry", [object_id, f"{mesh.name}\x00\x01Geometry", "Mesh"], children)


def scene_bytes(meshes: list[MeshNode], parents: list[int | None] | None = None, up_axis: int = 1,
                unit_cm: float = 100.0, compress: bool = False) -> bytes:
    """A binary FBX of mesh nodes ``meshes``; ``parents[i]`` the index of node i's parent (None: the root);
    ``up_axis`` 0, 1 or 2 (x, y, z) and ``unit_cm`` centimetres a unit (FBX ``UnitScaleFactor``);
    ``compress``: arrays zlib-compressed."""
    parents = parents or [None] * len(meshes)
    objects, connections, materials = [], [], {}
    model_id = lambda i: 2000 + i
    for i, mesh in enumerate(meshes):
        if mesh.geometry is None:
            objects.append(_geometry(mesh, 1000 + i))
        objects.append(Node("Model", [model_id(i), f"{mesh.name}\x00\x01Model", "Mesh"], [
            Node("Version", [232]),
            Node("Properties70", [], [
                Node("P", ["Lcl Translation", "Lcl Translation", "", "A", *map(float, mesh.translation)])])]))
        connections.append(Node("C", ["OO", 1000 + (i if mesh.geometry is None else mesh.geometry), model_id(i)]))
        parent = parents[i]
        connections.append(Node("C", ["OO", model_id(i), 0 if parent is None else model_id(parent)]))
        for name in mesh.materials:
            if name not in materials:
                materials[name] = 3000 + len(materials)
                objects.append(Node("Material", [materials[name], f"{name}\x00\x01Material", ""],
                                    [Node("Version", [102])]))
            connections.append(Node("C", ["OO", materials[name], model_id(i)]))
    settings = Node("GlobalSettings", [], [Node("Version", [1000]), Node("Properties70", [], [
        Node("P", ["UpAxis", "int", "Integer", "", up_axis]),
        Node("P", ["UpAxisSign", "int", "Integer", "", 1]),
        Node("P", ["FrontAxis", "int", "Integer", "", 2]),
        Node("P", ["FrontAxisSign", "int", "Integer", "", 1]),
        Node("P", ["CoordAxis", "int", "Integer", "", 0]),
        Node("P", ["CoordAxisSign", "int", "Integer", "", 1]),
        Node("P", ["UnitScaleFactor", "double", "Number", "", float(unit_cm)])])])
    return document([
        Node("FBXHeaderExtension", [], [Node("FBXHeaderVersion", [1003]), Node("FBXVersion", [7400])]),
        settings,
        Node("Objects", [], objects),
        Node("Connections", [], connections),
    ], compress)
