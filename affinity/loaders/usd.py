"""USD stages (``.usd``, ``.usda``, ``.usdc``, ``.usdz``) through usd-core (``pxr``).

``pxr`` is imported inside :func:`load_usd` only: without the ``usd`` extra,
every other format still works and a USD file gets one line naming the install
command.

A stage loads as one :class:`~affinity.mesh.Mesh` that concatenates every
``UsdGeom.Mesh`` prim in traversal order, instance proxies included (each
instance of a mesh is its own prim path), skipping prims that are invisible or
have ``guide``/``proxy`` purpose. Each prim is one group named by its prim path,
and ``Mesh.prim_face_start`` says which faces are whose, so findings point at a
prim and a face counted within it. ``PointInstancer`` copies are not expanded:
the prototype meshes are checked once, where they are defined, and the stage
gets a note.

Mapping to the mesh model, per prim:

- points in world space (``UsdGeom.XformCache``), at the earliest time sample
  unless :attr:`UsdOptions.time` says otherwise; every other value is read at
  the same time;
- ``faceVertexCounts``/``faceVertexIndices`` as faces of any size, the stored
  cage as is (``subdivisionScheme`` and ``holeIndices`` are not applied; a stage
  with Catmull-Clark or Loop meshes, USD's default, gets one note saying the
  findings are for the cage);
- where the points and topology are authored (:func:`~affinity.loaders.usdlayers.geometry_source`), so prims
  that reference one geometry layer can be reported once, at that layer;
- ``orientation = "leftHanded"`` reverses every face's winding, keeping corner 0
  (``a b c d`` becomes ``a d c b``): the split diagonal 0-2 stays the one a
  renderer triangulates along;
- primvars of every interpolation, indexed or not, become per-corner indices
  into their values (:func:`corner_index`): texture coordinates from ``st``, else
  the first ``texCoord2*`` primvar (or the one named by
  :attr:`UsdOptions.uv_primvar`), normals from ``primvars:normals``, else
  ``normals`` (unit length, in world space through the inverse transpose);
- ``displayColor`` as the model's per-vertex colours. Constant, vertex and
  varying colours are per vertex already; uniform and faceVarying colours split
  a vertex where the faces around it give it different colours, as a PLY file
  stores a colour seam. Prims without the attribute get -1 indices (uv,
  normals) or NaN colours, so their quads are not measured for it.

``upAxis`` and ``metersPerUnit`` are recorded on the mesh.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, replace

import numpy as np

from ..errors import MeshError, SkippedFile
from ..mesh import Mesh
from .formats import format_named
from .numbers import out_of_range, out_of_range_reason
from .resources import Resource
from .usddiagnostics import captured_diagnostics
from .usdlayers import (
    geometry_source,
    holds_look,
    layer_assets,
    may_hold_mesh,
    prim_type_names,
    regular_layers,
    subdivision_note,
)

USD_SUFFIXES = format_named("usd").suffixes
INSTALL = "pip install 'quad-affinity[usd]'"

_TEXCOORD2 = ("texCoord2f[]", "texCoord2d[]", "texCoord2h[]")
_HIDDEN_PURPOSES = ("guide", "proxy")
_INTERNAL_NAME = re.compile(r"pxrInternal_v\w+?__pxrReserved__::")
_TEXT_LINE = re.compile(r"\.usda?:(\d+):\d+: ")


@dataclass(frozen=True)
class UsdOptions:
    """How to read a stage: ``time`` (None: the earliest time sample), the uv primvar
    name (None: ``st``, else the first ``texCoord2*`` primvar) and whether the textures of every
    variant's material binding are read (``all_variants``; default: the stage's selection)."""

    time: float | None = None
    uv_primvar: str | None = None
    all_variants: bool = False


class _BadPrim(Exception):
    """A problem with one mesh prim; :func:`load_usd` adds the file and the prim path."""


@dataclass(frozen=True)
class _Primvar:
    """Values of one primvar: ``values`` (n, K), ``indices`` (m,) int or None."""

    name: str
    values: np.ndarray
    interpolation: str
    indices: np.ndarray | None = None


def load_usd(path, options: UsdOptions | None = None) -> Mesh:
    """Read every drawn mesh prim of the USD stage at ``path`` as one mesh (see the module docstring).

    Raises MeshError (line 0, the prim path in the reason) when usd-core is
    missing, the stage cannot be opened or traversed, or a prim's topology or
    values are invalid; SkippedFile (``no-mesh``) when it has no mesh to check and no look (a stage
    whose layers hold materials or bindings, :func:`~affinity.loaders.usdlayers.holds_look`, is an empty
    mesh: checked, without findings). A stage none of whose
    layers holds a prim spec that may be a mesh (:func:`~affinity.loaders.usdlayers.may_hold_mesh`) is
    skipped without composing it: on a stage of 100,000 empty prims composing took 1.2 s, the look
    at the layer's specs 0.23 s.
    """
    try:
        from pxr import Tf, Usd
    except ImportError:
        raise MeshError(path, 0, f"reading USD needs usd-core: {INSTALL}") from None
    said: list[str] = []  # usd-core's diagnostics, one note per problem
    with captured_diagnostics(os.getcwd(), said):
        try:
            layers, complete = regular_layers(path)  # held open until the stage is: pxr reads each once
            type_names = [prim_type_names(layer) for layer in layers]
            look = any(map(holds_look, layers, type_names))
            if complete and not any(map(may_hold_mesh, type_names)):
                stage = None
            else:
                stage = Usd.Stage.Open(os.fspath(path))
            del layers
        except Tf.ErrorException as error:
            reason = pxr_reason(error)
            line = _TEXT_LINE.search(reason)  # .usda parse errors say where: "file.usda:7:9: ..."
            raise MeshError(path, int(line.group(1)) if line else 0, f"cannot open the stage: {reason}") from None
        try:
            if stage is None:
                raise SkippedFile(path, "no-mesh")
            mesh = load_stage(stage, os.fspath(path), options)
        except SkippedFile:
            if not look:
                raise
            mesh = _look_only(path)
    mesh.notes += said
    mesh.resources = [Resource(role="usd-asset", name=asset, path=os.path.normpath(absolute))
                      for asset, absolute in layer_assets(path)]
    return mesh


def _look_only(path) -> Mesh:
    """The empty mesh of a stage whose layers hold a look and no mesh: a checked file without findings
    (design.md, Clarifications), not a skip."""
    return Mesh(path=os.fspath(path), positions=np.zeros((0, 3)), face_start=np.zeros(1, dtype=np.int64),
                corner_vertex=np.zeros(0, dtype=np.int64), face_line=np.zeros(0, dtype=np.int64), group_names=[],
                prim_face_start=np.zeros(1, dtype=np.int64))


def load_stage(stage, path: str, options: UsdOptions | None = None, prim_paths: list[str] | None = None,
               bad_prims: dict[str, str] | None = None) -> Mesh:
    """The drawn mesh prims of an open ``Usd.Stage`` as one mesh named ``path``: all of them, or those
    of ``prim_paths`` (in that order), as :func:`load_usd` reads a file.

    Raises MeshError and SkippedFile as :func:`load_usd` does. With ``bad_prims`` (a dict) a prim
    that cannot be read is left out and its path mapped to the reason there instead of raising.
    """
    from pxr import Tf, Usd, UsdGeom

    options = options or UsdOptions()
    time = Usd.TimeCode.EarliestTime() if options.time is None else Usd.TimeCode(options.time)
    try:
        xforms = UsdGeom.XformCache(time)
        if prim_paths is None:
            prims, notes = _mesh_prims(stage, time)
        else:
            prims, notes = [stage.GetPrimAtPath(prim_path) for prim_path in prim_paths], []
    except Tf.ErrorException as error:
        raise MeshError(path, 0, f"cannot read the stage: {pxr_reason(error)}") from None
    if not prims:  # a material, light or layout layer: nothing of ours to check
        raise SkippedFile(path, "no-mesh")
    parts, sources, read = [], [], []
    for prim in prims:
        try:
            part, source = _read_prim(prim, time, xforms, options.uv_primvar), \
                geometry_source(prim, time)
        except (_BadPrim, Tf.ErrorException) as error:
            reason = str(error) if isinstance(error, _BadPrim) else pxr_reason(error)
            if bad_prims is None:
                raise MeshError(path, 0, f"{prim.GetPath()}: {reason}") from None
            bad_prims[str(prim.GetPath())] = reason
            continue
        parts.append(part)
        sources.append(source)
        read.append(prim)
    if not read:  # every prim asked for was bad (and reported in bad_prims)
        raise SkippedFile(path, "no-mesh")
    prims = read
    subdivided = subdivision_note(prims, time)
    if subdivided:
        notes.append(subdivided)
    if options.uv_primvar and all(part.texcoords is None for part in parts):
        notes.append(f"no mesh has the primvar {options.uv_primvar!r}: texture coordinates not checked")
    mesh = _concatenate(path, parts, [str(prim.GetPath()) for prim in prims])
    mesh.prim_sources = sources
    mesh.up_axis = _stage_metadata(stage, "upAxis", lambda: str(UsdGeom.GetStageUpAxis(stage)), notes)
    mesh.meters_per_unit = _stage_metadata(stage, "metersPerUnit", lambda: float(UsdGeom.GetStageMetersPerUnit(stage)),
                                           notes)
    mesh.notes = notes
    _bind_materials(mesh, prims, options.uv_primvar, options.all_variants)
    return mesh


def _bind_materials(mesh: Mesh, prims: list, uv_primvar: str | None, all_variants: bool = False) -> None:
    """Each prim's bound material (``material_names``, ``face_material`` per prim) and the textures it reads
    through the uv primvar (``material_maps``, :mod:`affinity.loaders.usdmaterials`)."""
    from pxr import Tf

    from .usdmaterials import prim_material_maps

    names, per_prim = [], []
    for prim in prims:
        try:
            material, maps = prim_material_maps(prim, uv_primvar, all_variants)
        except Tf.ErrorException:
            material, maps = None, []
        if material is not None and material not in names:
            names.append(material)
            mesh.material_maps[material] = maps
        per_prim.append(names.index(material) if material is not None else -1)
    mesh.material_names = names
    sizes = np.diff(mesh.prim_face_start)
    mesh.face_material = np.repeat(np.asarray(per_prim, dtype=np.int32), sizes)


def _stage_metadata(stage, name: str, read, notes: list[str]):
    """``read()``, the stage's ``name`` metadata; None and a note when it cannot be read
    (e.g. a value of the wrong type): the meshes are checked all the same."""
    from pxr import Tf

    try:
        return read()
    except (Tf.ErrorException, TypeError, ValueError) as error:
        reason = pxr_reason(error) if isinstance(error, Tf.ErrorException) else str(error)
        notes.append(f"the stage's {name} cannot be read ({reason}): not recorded")
        return None


def pxr_reason(error) -> str:
    """The first (most specific) message of a ``Tf.ErrorException``, on one line."""
    text = getattr(error.args[0], "commentary", str(error)) if error.args else str(error)
    return " ".join(_INTERNAL_NAME.sub("", text).split())


def _mesh_prims(stage, time) -> tuple[list, list[str]]:
    """The mesh prims to check, in traversal order (instance proxies included), and notes
    on what was left out: hidden prims, PointInstancer copies."""
    from pxr import Usd, UsdGeom

    prims, hidden, notes = [], 0, []
    for prim in Usd.PrimRange(stage.GetPseudoRoot(), Usd.TraverseInstanceProxies()):
        if prim.IsA(UsdGeom.PointInstancer):
            instancer = UsdGeom.PointInstancer(prim)
            copies = len(instancer.GetProtoIndicesAttr().Get(time) or [])
            prototypes = len(instancer.GetPrototypesRel().GetTargets())
            notes.append(f"PointInstancer {prim.GetPath()}: {copies} copies of {prototypes} "
                         f"prototype{'s' * (prototypes != 1)} not expanded "
                         "(each prototype mesh is checked once, where it is defined)")
        elif prim.IsA(UsdGeom.Mesh):
            imageable = UsdGeom.Imageable(prim)
            if imageable.ComputeVisibility(time) == UsdGeom.Tokens.invisible or \
                    imageable.ComputePurpose() in _HIDDEN_PURPOSES:
                hidden += 1
            else:
                prims.append(prim)
    if hidden:
        notes.insert(0, f"{hidden} mesh prim{'s' * (hidden != 1)} skipped (invisible, or guide/proxy purpose)")
    return prims, notes


def _array(attribute, time, dtype, width: int | None = None) -> np.ndarray:
    """The ``Vt`` array value of ``attribute`` at ``time`` (empty when unauthored) as NumPy: (n,) or (n, width);
    _BadPrim when it is of another type (``string points``: not numbers, or not ``width`` of them)."""
    shape = (-1,) if width is None else (-1, width)
    value = attribute.Get(time)
    try:
        return np.asarray([] if value is None else value, dtype=dtype).reshape(shape)
    except (ValueError, TypeError):
        raise _BadPrim(f"{attribute.GetName()} holds {type(value).__name__} values, not "
                       f"{'numbers' if width is None else f'{width}-component values'}") from None


def _finite(name: str, values: np.ndarray) -> np.ndarray:
    if out_of_range(values).any():
        if np.isfinite(values).all():
            raise _BadPrim(f"{name}: {out_of_range_reason(values[out_of_range(values)][0])}")
        raise _BadPrim(f"{name} has NaN or Inf values")
    return values


def _read_prim(prim, time, xforms, uv_primvar: str | None) -> Mesh:
    """One mesh prim in world space, corners in right-handed order (see the module docstring)."""
    from pxr import UsdGeom

    usd_mesh = UsdGeom.Mesh(prim)
    points_attribute = usd_mesh.GetPointsAttr()
    points = _finite("points", _array(points_attribute, time, np.float64, 3))
    sizes = _array(usd_mesh.GetFaceVertexCountsAttr(), time, np.int64)
    corner_vertex = _array(usd_mesh.GetFaceVertexIndicesAttr(), time, np.int64)
    _check_topology(sizes, corner_vertex, len(points))
    face_start = np.concatenate(([0], np.cumsum(sizes)))
    matrix = np.array(xforms.GetLocalToWorldTransform(prim))  # (4, 4), row vectors: p' = p M
    topology = (len(points), sizes, corner_vertex)

    primvars = UsdGeom.PrimvarsAPI(prim)
    uv = _uv_primvar(primvars, time, uv_primvar)
    normals = _normals(usd_mesh, primvars, time)
    color = _primvar(primvars.FindPrimvarWithInheritance("displayColor"), time, width=3)
    corner_texcoord = None if uv is None else corner_index(uv, *topology)
    corner_normal = None if normals is None else corner_index(normals, *topology)
    corner_color = None if color is None else corner_index(color, *topology)

    if usd_mesh.GetOrientationAttr().Get(time) == UsdGeom.Tokens.leftHanded:
        order = reversed_winding(face_start)
        corner_vertex, corner_texcoord, corner_normal, corner_color = (
            None if index is None else index[order]
            for index in (corner_vertex, corner_texcoord, corner_normal, corner_color))
    positions = _transformed(points, matrix[:3, :3]) + matrix[3, :3]
    colors = None
    scheme = subdivision_scheme(usd_mesh, time)
    if color is not None:
        n_points = len(positions)
        positions, corner_vertex, colors = colors_per_vertex(positions, corner_vertex, corner_color, color.values)
        if len(positions) != n_points:  # vertices split by colour: crease indices no longer name them
            scheme = replace(scheme, crease_edges=scheme.crease_edges[:0], crease_sharpness=scheme.crease_sharpness[:0],
                             corner_vertices=scheme.corner_vertices[:0],
                             corner_sharpness=scheme.corner_sharpness[:0])
    return Mesh(
        path=str(prim.GetPath()),
        positions=positions,
        face_start=face_start,
        corner_vertex=corner_vertex,
        face_line=np.zeros(len(sizes), dtype=np.int64),
        texcoords=None if uv is None else uv.values,
        corner_texcoord=corner_texcoord,
        normals=None if normals is None else world_normals(normals.values, matrix[:3, :3]),
        corner_normal=corner_normal,
        colors=colors,
        subdivision=[scheme],
        position_epsilon=_epsilon(points_attribute),
    )


def subdivision_scheme(usd_mesh, time):
    """How a ``UsdGeom.Mesh`` subdivides, as an :class:`affinity.subdivision.Scheme`: its scheme and rules
    (authored, or USD's fallbacks: catmullClark, edgeAndCorner, cornersPlus1), its creases (chains of
    ``creaseLengths`` vertices, one sharpness a chain or an edge), corners and holes."""
    from ..subdivision import BOUNDARY_RULES, SCHEMES, Scheme
    from ..subdivision.facevarying import RULES

    def tokens(attr, allowed, fallback):
        value = str(attr.Get(time) or fallback)
        return value if value in allowed else fallback

    indices = _array(usd_mesh.GetCreaseIndicesAttr(), time, np.int64)
    lengths = _array(usd_mesh.GetCreaseLengthsAttr(), time, np.int64)
    sharpness = _array(usd_mesh.GetCreaseSharpnessesAttr(), time, np.float64)
    edges, edge_sharpness = np.zeros((0, 2), dtype=np.int64), np.zeros(0)
    if len(lengths) and lengths.sum() == len(indices) and (lengths >= 2).all():
        starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])
        chain = np.repeat(np.arange(len(lengths)), lengths - 1)
        first = np.concatenate([np.arange(s, s + n - 1) for s, n in zip(starts, lengths)])
        edges = np.stack([indices[first], indices[first + 1]], axis=1)
        if len(sharpness) == len(lengths):
            edge_sharpness = sharpness[chain]
        elif len(sharpness) == len(edges):
            edge_sharpness = sharpness
        else:
            edges = edges[:0]
    corners = _array(usd_mesh.GetCornerIndicesAttr(), time, np.int64)
    corner_sharpness = _array(usd_mesh.GetCornerSharpnessesAttr(), time, np.float64)
    if len(corners) != len(corner_sharpness):
        corners, corner_sharpness = corners[:0], corner_sharpness[:0]
    return Scheme(scheme=tokens(usd_mesh.GetSubdivisionSchemeAttr(), SCHEMES, "catmullClark"),
                  boundary=tokens(usd_mesh.GetInterpolateBoundaryAttr(), BOUNDARY_RULES, "edgeAndCorner"),
                  fvar=tokens(usd_mesh.GetFaceVaryingLinearInterpolationAttr(), RULES, "cornersPlus1"),
                  crease_edges=edges, crease_sharpness=edge_sharpness, corner_vertices=corners,
                  corner_sharpness=corner_sharpness,
                  holes=_array(usd_mesh.GetHoleIndicesAttr(), time, np.int64))


def _epsilon(attribute) -> float:
    """The machine epsilon of the points as ``attribute`` stores them: float16 for ``point3h[]``, float32 for
    ``point3f[]`` (USD's usual), float64 for ``point3d[]`` and anything else."""
    name = str(attribute.GetTypeName())
    dtype = np.float16 if "3h" in name else np.float32 if "3f" in name else np.float64
    return float(np.finfo(dtype).eps)


def _transformed(rows: np.ndarray, linear: np.ndarray) -> np.ndarray:
    """(N, 3) row vectors times a (3, 3) matrix. einsum, not ``@``: the first BLAS call of
    a process pays OpenBLAS's start-up (measured 0.3 s on 1M points, 0.04 s with einsum)."""
    return np.einsum("ij,jk->ik", rows, linear)


def world_normals(normals: np.ndarray, linear: np.ndarray) -> np.ndarray:
    """(N, 3) unit normals in world space, through the inverse transpose of the
    prim's (3, 3) ``linear`` transform (row vectors; pseudo-inverse, so a prim
    scaled to zero does not fail). Zero normals stay zero.

    >>> world_normals(np.array([[0.0, 0, 1], [1, 0, 0]]), np.diag([2.0, 2, 4])).tolist()
    [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
    """
    world = _transformed(normals, np.linalg.pinv(linear).T)
    length = np.sqrt(np.einsum("ij,ij->i", world, world))[:, None]
    return np.divide(world, length, out=world, where=length > 0)


def _check_topology(sizes: np.ndarray, corner_vertex: np.ndarray, n_points: int) -> None:
    if len(sizes) and sizes.min() < 3:
        raise _BadPrim(f"faceVertexCounts has a face with {sizes.min()} corners (at least 3 needed)")
    if sizes.sum() != len(corner_vertex):
        raise _BadPrim(f"faceVertexCounts add up to {sizes.sum()} corners but faceVertexIndices has "
                       f"{len(corner_vertex)} entries")
    if len(corner_vertex) and (corner_vertex.min() < 0 or corner_vertex.max() >= n_points):
        raise _BadPrim(f"faceVertexIndices has an entry outside the {n_points} points")


def _primvar(primvar, time, width: int) -> _Primvar | None:
    """A primvar's values (n, width) float64, finite, and indices at ``time``; None when it has no value."""
    if not primvar or not primvar.HasValue():
        return None
    name = primvar.GetAttr().GetName()
    values = primvar.Get(time)
    try:
        values = np.asarray([] if values is None else values, dtype=np.float64)
    except (ValueError, TypeError):
        raise _BadPrim(f"{name} holds {type(values).__name__} values, not {width}-component values") from None
    if values.size and (values.ndim != 2 or values.shape[1] != width):
        raise _BadPrim(f"{name} is {primvar.GetTypeName()}, not {width}-component values")
    values = values.reshape(-1, width)
    indices = _array(primvar.GetIndicesAttr(), time, np.int64) if primvar.IsIndexed() else None
    return _Primvar(name, _finite(name, values), str(primvar.GetInterpolation()), indices)


def _uv_primvar(primvars, time, name: str | None) -> _Primvar | None:
    """The texture coordinates: primvar ``name``, else ``st``, else the first texCoord2* primvar."""
    chosen = primvars.FindPrimvarWithInheritance(name or "st")
    if name is None and not (chosen and chosen.HasValue()):
        chosen = next((pv for pv in primvars.FindPrimvarsWithInheritance()
                       if str(pv.GetTypeName()) in _TEXCOORD2 and pv.HasValue()), None)
    return _primvar(chosen, time, width=2)


def uv_primvar_name(prim, time, name: str | None = None) -> str | None:
    """The attribute name (``primvars:st``) of the primvar the loader reads as ``prim``'s texture
    coordinates, with :attr:`UsdOptions.uv_primvar` ``name``; None when it has none."""
    from pxr import UsdGeom

    uv = _uv_primvar(UsdGeom.PrimvarsAPI(prim), time, name)
    return None if uv is None else uv.name


def _normals(usd_mesh, primvars, time) -> _Primvar | None:
    """``primvars:normals`` when authored (it wins, as in UsdGeom), else the ``normals`` attribute."""
    normals = _primvar(primvars.GetPrimvar("normals"), time, width=3)
    if normals is not None or not usd_mesh.GetNormalsAttr().HasValue():
        return normals
    values = _finite("normals", _array(usd_mesh.GetNormalsAttr(), time, np.float64, 3))
    return _Primvar("normals", values, str(usd_mesh.GetNormalsInterpolation()))


def corner_index(primvar: _Primvar, n_points: int, sizes: np.ndarray, corner_vertex: np.ndarray) -> np.ndarray:
    """(C,) int64 index into ``primvar.values`` for every corner, whatever the interpolation.

    ``sizes`` (F,) are the corners per face and ``corner_vertex`` (C,) the point
    of each corner. Without indices, the values must number exactly what the
    interpolation needs (1 constant, F uniform, P vertex/varying, C faceVarying);
    with indices, the indices must, and they must lie within the values.

    >>> pv = _Primvar("primvars:st", np.zeros((2, 2)), "uniform", np.array([1, 0]))
    >>> corner_index(pv, 4, np.array([3, 3]), np.array([0, 1, 2, 0, 2, 3])).tolist()
    [1, 1, 1, 0, 0, 0]
    """
    n_corners = len(corner_vertex)
    needed, per_corner = {
        "constant": (1, lambda: np.zeros(n_corners, dtype=np.int64)),
        "uniform": (len(sizes), lambda: np.repeat(np.arange(len(sizes)), sizes)),
        "vertex": (n_points, lambda: corner_vertex),
        "varying": (n_points, lambda: corner_vertex),
        "faceVarying": (n_corners, lambda: np.arange(n_corners)),
    }.get(primvar.interpolation, (None, None))
    if needed is None:
        raise _BadPrim(f"{primvar.name} has the unknown interpolation {primvar.interpolation!r}")
    counted, what = (primvar.values, "values") if primvar.indices is None else (primvar.indices, "indices")
    if len(counted) != needed:
        raise _BadPrim(f"{primvar.name} has {len(counted)} {what}; {primvar.interpolation} interpolation "
                       f"needs {needed} here")
    if primvar.indices is None:
        return per_corner()
    if needed and (primvar.indices.min() < 0 or primvar.indices.max() >= len(primvar.values)):
        raise _BadPrim(f"{primvar.name}:indices has an entry outside the {len(primvar.values)} values")
    return primvar.indices[per_corner()]


def reversed_winding(face_start: np.ndarray) -> np.ndarray:
    """(C,) int64 corner order that reverses every face's winding and keeps its corner 0.

    face_start : (F + 1,) int64. Corner ``k`` of a face of ``n`` takes the values of
    its corner ``(n - k) % n``.

    >>> reversed_winding(np.array([0, 4, 7])).tolist()
    [0, 3, 2, 1, 4, 6, 5]
    """
    sizes = np.diff(face_start)
    first = np.repeat(face_start[:-1], sizes)
    k = np.arange(face_start[-1]) - first
    return first + (-k) % np.repeat(sizes, sizes)


def colors_per_vertex(positions, corner_vertex, corner_color, values) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-corner colours as per-vertex colours, splitting vertices whose corners disagree.

    positions (V, 3), corner_vertex (C,), corner_color (C,) index into values (K, 3).
    Returns positions (V', 3) with a copy of a vertex for each further colour it
    has, corner_vertex (C,) and colours (V', 3), NaN for vertices no corner uses.

    >>> p, cv, c = colors_per_vertex(np.zeros((3, 3)), np.array([0, 1, 2, 0]), np.array([0, 0, 0, 1]), np.eye(3))
    >>> len(p), c[cv, 0].tolist()  # vertex 0 split in two; every corner keeps its colour
    (4, [1.0, 1.0, 1.0, 0.0])
    """
    color_of_vertex = np.full(len(positions), -1, dtype=np.int64)
    color_of_vertex[corner_vertex] = corner_color  # one of each vertex's corners wins
    differs = color_of_vertex[corner_vertex] != corner_color
    if differs.any():
        pairs, inverse = np.unique(corner_vertex[differs] * len(values) + corner_color[differs], return_inverse=True)
        corner_vertex = corner_vertex.copy()
        corner_vertex[differs] = len(positions) + inverse.reshape(-1)
        positions = np.concatenate([positions, positions[pairs // len(values)]])
        color_of_vertex = np.concatenate([color_of_vertex, pairs % len(values)])
    colors = values[color_of_vertex]
    colors[color_of_vertex < 0] = np.nan
    return positions, corner_vertex, colors


def _stacked(arrays: list[np.ndarray]) -> np.ndarray:
    """The arrays one after the other; the array itself when there is one (a stage of one big mesh)."""
    return arrays[0] if len(arrays) == 1 else np.concatenate(arrays)


def _joined(values: list, indices: list, corners: list[int]) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Per-prim indexed attributes as one: values (sum n, K) stacked, each prim's indices
    (C_p,) shifted past the values before it, -1 for the corners of prims without the
    attribute; (None, None) when no prim has it."""
    if all(v is None for v in values):
        return None, None
    joined = np.empty(sum(corners), dtype=np.int64)
    start, offset = 0, 0
    for value, index, n in zip(values, indices, corners):
        if index is None:
            joined[start:start + n] = -1
        else:
            np.add(index, offset, out=joined[start:start + n])
            offset += len(value)
        start += n
    return _stacked([v for v in values if v is not None]), joined


def _concatenate(path: str, parts: list[Mesh], prim_paths: list[str]) -> Mesh:
    """The prims' meshes as one mesh of ``path``: group ``p`` is prim ``prim_paths[p]``."""
    corners = [len(p.corner_vertex) for p in parts]
    positions, corner_vertex = _joined([p.positions for p in parts], [p.corner_vertex for p in parts], corners)
    texcoords, corner_texcoord = _joined([p.texcoords for p in parts], [p.corner_texcoord for p in parts], corners)
    normals, corner_normal = _joined([p.normals for p in parts], [p.corner_normal for p in parts], corners)
    colors = None
    if any(p.colors is not None for p in parts):
        colors = _stacked([np.full((len(p.positions), 3), np.nan) if p.colors is None else p.colors for p in parts])
    faces = [p.n_faces for p in parts]
    corner_offsets = np.cumsum([0] + corners)
    return Mesh(
        path=path,
        positions=positions,
        face_start=_stacked([np.zeros(1, dtype=np.int64)]
                            + [p.face_start[1:] + offset for p, offset in zip(parts, corner_offsets)]),
        corner_vertex=corner_vertex,
        face_line=np.zeros(sum(faces), dtype=np.int64),  # a stage has no source lines
        group_names=prim_paths,  # one group per mesh prim, its faces from prim_face_start on
        face_group=np.repeat(np.arange(len(parts), dtype=np.int32), faces),
        prim_face_start=np.cumsum([0] + faces, dtype=np.int64),
        colors=colors,
        texcoords=texcoords, corner_texcoord=corner_texcoord,
        normals=normals, corner_normal=corner_normal,
        subdivision=_offset_schemes(parts),
        position_epsilon=max(p.position_epsilon for p in parts),
    )


def _offset_schemes(parts: list[Mesh]) -> list | None:
    """The prims' :class:`affinity.subdivision.Scheme` with vertex and face indices into the joined mesh."""
    if any(p.subdivision is None for p in parts):
        return None
    vertex = np.cumsum([0] + [len(p.positions) for p in parts])
    face = np.cumsum([0] + [p.n_faces for p in parts])
    return [replace(scheme, crease_edges=scheme.crease_edges + v, corner_vertices=scheme.corner_vertices + v,
                    holes=scheme.holes + f)
            for p, v, f in zip(parts, vertex, face) for scheme in p.subdivision]
