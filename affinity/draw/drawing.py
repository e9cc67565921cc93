"""A mesh, a view, an image: ``render_mesh`` with its options and result records.

``render_mesh`` loads a mesh, frames it (:mod:`.framing`), turns it into the
renderer's quads (:mod:`.quads`), picks the method of every quad (one method, or
the hybrid's per-quad routing, :mod:`.routing`), calls ``render.rasterize_quads``
and shades the result (:mod:`.shading`).
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np

from ..attributes import drawn_attribute
from ..mesh import Mesh
from ..settings import Settings
from .framing import camera_for
from .quads import render_corners
from .routing import MVC, SPLIT, route_by_view
from .shading import OVERLAY_TINT, ShadingInputs, shade, shading_inputs

#: Quads (and triangles) one render draws: on the way to the rasterizer each holds about 1 KB (its
#: corners, attributes, clip coordinates and route; 985 MB peak measured for a million triangles,
#: the mesh included), so a render stays near 2 GB; a bigger mesh stops with ``render.raster.OverBudget``
#: (a ValueError) saying so.
MAX_RENDER_QUADS = 1 << 21

if TYPE_CHECKING:
    from render.camera import Camera


@dataclass
class RenderOptions:
    """How to render (``affinity render`` has a flag for each field but ``settings``).

    Attributes
    ----------
    method : str
        ``"hybrid"`` (split where the split is invisible, mvc elsewhere), or one
        method for every quad: ``"split"``, ``"mvc"``, ``"bilinear"``,
        ``"projective"``, ``"exact"`` (see ``render.rasterize_quads``).
    route : str
        How the hybrid decides, for uv: ``"view"`` (the split's texture
        displacement in this view, in pixels, :mod:`.routing`) or ``"lint"``
        (the quads the lint's uv rule flags). Colours and normals always route by
        their lint rule.
    pixel_tolerance : float
        Route ``"view"``: a quad goes to mvc when the split moves its texture by
        more than this many pixels.
    width, height : int
        Image size in pixels.
    camera : ((ex, ey, ez), (tx, ty, tz), fov_deg) or None
        Eye, target and vertical field of view in degrees; None frames the whole mesh.
    up : ``"x"``, ``"y"``, ``"z"`` or None
        World up axis; None: the file's (a USD stage's upAxis), else y.
    show : ``"uv"``, ``"color"``, ``"normal"``, ``"shaded"`` or None
        What to draw; None: uv when the mesh has it, else colours, else shading.
    texture : str, (h, w, 3) float RGB array, or None
        The texture for uv: an image path (its errors are fatal), an image; None:
        the mesh's ``map_Kd`` (a missing one warns), else the checker.
    overlay : bool
        ``image`` is ``tinted``: the pixels of the quads sent to mvc tinted.
    cull : bool
        Cull back faces.
    settings : affinity.settings.Settings or None
        The lint settings routing reads (rule thresholds and ignores, Q301's
        threshold for degenerate uv quads); the diagonal is always 0-2, the
        renderer's split. None: the settings governing the mesh's file as
        ``affinity check`` resolves them (``affinity.config.file_settings``), the
        defaults for a mesh read from no file.
    """

    method: str = "hybrid"
    route: str = "view"
    pixel_tolerance: float = 0.5
    width: int = 800
    height: int = 600
    camera: tuple | None = None
    up: str | None = None
    show: str | None = None
    texture: str | np.ndarray | None = None
    overlay: bool = False
    cull: bool = False
    settings: Settings | None = None


@dataclass
class RenderResult:
    """A finished render, with what it was drawn from.

    Attributes
    ----------
    mesh : the Mesh drawn
    image : (H, W, 3) float32 RGB in [0, 1] (``tinted`` with ``RenderOptions.overlay``)
    frame : render.Frame, ``face`` indexes the render quads
    faces : (R,) int64, the mesh face of each render quad
    methods : (R,) str, the method each render quad was drawn with (the hybrid's routes)
    method : the ``RenderOptions.method`` asked for
    seconds : float, routing plus rasterizing time
    camera : render.camera.Camera the quads were seen with (``matrix`` (4, 4), ``eye``, ``target``)
    clip : (R, 4, 4) float64, the render quads' clip-space corners (x, y, z, w) as rasterized
    inputs : affinity.draw.shading.ShadingInputs, the per-corner attributes (R, 4, K) rasterized
    tinted : (H, W, 3) float32, the image with the pixels of the quads sent to mvc tinted
    settings : the lint Settings the routing read
    """

    mesh: Mesh
    image: np.ndarray
    frame: object
    faces: np.ndarray
    methods: np.ndarray
    method: str
    seconds: float
    camera: Camera
    clip: np.ndarray
    inputs: ShadingInputs
    tinted: np.ndarray
    settings: Settings

    @property
    def mvc_pixels(self) -> np.ndarray:
        """(H, W) bool: the covered pixels drawn by quads sent to mvc."""
        return mvc_pixels(self.frame.face, self.methods)

    def summary(self) -> str:
        """One line: where the quads went and how long the render took."""
        if self.method != "hybrid":
            return f"{self.mesh.path}: {self.method}: all {len(self.methods)} quads ({self.seconds:.2f} s)"
        mvc = int(np.count_nonzero(self.methods == MVC))
        return (f"{self.mesh.path}: hybrid: {mvc} of {len(self.methods)} quads to mvc, "
                f"{len(self.methods) - mvc} to split ({self.seconds:.2f} s)")

    def save_png(self, path: str) -> None:
        """Write the image as PNG, atomically (Pillow)."""
        from .png import to_pixels, write_png

        write_png(path, to_pixels(self.image))


def mvc_pixels(face: np.ndarray, methods: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pixels whose render quad (``face`` (H, W) int, -1 empty) was drawn with mvc
    (``methods`` (R,) str)."""
    return (face >= 0) & (methods[np.maximum(face, 0)] == MVC)


def uv_routing_inputs(mesh: Mesh, faces: np.ndarray, uv: np.ndarray, settings: Settings):
    """The view-independent part of routing by view (``affinity.draw.routing``), once per mesh:
    the split's texture displacement of every render quad, and the lint's uv error
    (along 0-2, uv units) per render quad when some uv quad is degenerate (Q301 at
    the threshold of ``settings``), else None."""
    from ..rules.texture import UV_DEGENERATE
    from .routing import uv_displacement

    moves = uv_displacement(uv, settings.threshold(UV_DEGENERATE))
    uv_error = None
    if moves.degenerate.any():
        from ..lint import quad_uv_error

        quad_faces, error = quad_uv_error(mesh, diagonal="02")
        per_face = np.zeros(mesh.n_faces)
        per_face[quad_faces] = np.nan_to_num(error)
        uv_error = per_face[faces]
    return moves, uv_error


def choose_methods(mesh: Mesh, faces: np.ndarray, uv: np.ndarray | None, clip: np.ndarray,
                   show: str, options: RenderOptions, settings: Settings) -> np.ndarray:
    """The method of every render quad: one name, or the hybrid's per-quad routing.

    ``uv`` (R, 4, 2) is the render quads' texture coordinates when the render
    shows them, else None. Routing by view projects the split's largest texture
    displacement (along the renderer's diagonal 0-2) to pixels; for colours and
    normals, and with ``--route lint``, the lint rule of the attribute shown decides, as
    ``settings`` configure it (along 0-2).
    """
    if options.method != "hybrid":
        return np.full(len(faces), options.method)
    routes_uv = uv is not None
    if options.route == "view" and routes_uv:
        moves, uv_error = uv_routing_inputs(mesh, faces, uv, settings)
        return route_by_view(moves, uv, clip, options.width, options.height,
                             options.pixel_tolerance, options.cull, uv_error)
    from ..lint import quad_scores, scored_codes
    from ..rules import resolve_codes

    code = scored_codes(attribute="uv" if routes_uv else ("color" if show == "color" else "normal"))[0]
    flagged = np.zeros(mesh.n_faces, dtype=bool)
    if resolve_codes([code], settings.ignore):  # an ignored rule sends nothing to mvc
        scores = quad_scores(mesh, replace(settings, diagonal="02"), code)
        flagged[scores.faces[scores.flagged]] = True
    return np.where(flagged[faces], MVC, SPLIT)


def resolve_texture(mesh: Mesh, options: RenderOptions, warn: Callable[[str], None]) -> np.ndarray:
    """The explicit texture (an image, or a path whose errors are fatal), else map_Kd (a missing
    one warns), else the checker."""
    from .texture import TextureError, checker, load_image, painted_texture

    if isinstance(options.texture, np.ndarray):
        return options.texture
    if options.texture:
        return load_image(options.texture)
    path = painted_texture(mesh)
    if path:
        try:
            return load_image(path)
        except TextureError as err:
            warn(f"{err}; using the checker texture")
        return checker()
    from ..rules.file import unusable_resource

    for library in (r for r in mesh.resources if r.role == "mtllib"):  # why no map_Kd was found
        problem = unusable_resource(library.path, image=False)
        if problem:
            warn(f"{library.path}: mtllib {problem}; using the checker texture")
    return checker()


def over_render_budget(mesh: Mesh) -> str | None:
    """Why ``mesh`` is not drawn (more quads and triangles than :data:`MAX_RENDER_QUADS`), or None."""
    sizes = mesh.face_sizes
    drawn = int(np.where(sizes == 4, 1, sizes - 2).sum())  # quads, and triangles of triangles and fans
    if drawn <= MAX_RENDER_QUADS:
        return None
    return (f"{mesh.path}: {drawn:,} quads and triangles to draw, over the renderer's budget of "
            f"{MAX_RENDER_QUADS:,} (about 1 KB of memory each): render a part of the mesh")


def render_mesh(source: str | Mesh | None, options: RenderOptions,
                warn: Callable[[str], None] = lambda line: None) -> RenderResult:
    """Route, rasterize and shade a mesh: a path to load, a loaded Mesh, or None for the demo.

    Raises
    ------
    MeshError for an unreadable mesh; TextureError for an explicit texture that
    cannot be read; ValueError for a mesh that cannot be rendered (no faces,
    everything behind the camera, nothing of what ``show`` needs).
    """
    from render import rasterize_quads, to_clip
    from render.raster import OverBudget

    from ..config import file_settings
    from ..loaders import load
    from ..scenes import DEMO_SPHERE

    if source is None:
        mesh, view = DEMO_SPHERE.mesh(), DEMO_SPHERE.view
        options = replace(options, camera=options.camera or view.camera, up=options.up or view.up)
    else:
        mesh = load(source) if isinstance(source, (str, os.PathLike)) else source
    settings = options.settings or file_settings(mesh.path)
    if mesh.n_faces == 0:
        raise ValueError(f"{mesh.path}: the mesh has no faces to render")
    show = options.show or drawn_attribute(mesh)
    problem = over_render_budget(mesh)
    if problem:
        raise OverBudget(problem)
    faces, corners = render_corners(mesh)
    inputs = shading_inputs(mesh, corners, show)
    camera = camera_for(mesh, options.width, options.height, options.camera, options.up)
    used = mesh.corner_vertex[corners]
    # A close-up's subset uses a few of the vertices: transform its corners, not the whole table.
    clip = (to_clip(mesh.positions[used], camera.matrix) if used.size < len(mesh.positions)
            else to_clip(mesh.positions, camera.matrix)[used])
    if not (clip[..., 3] > 0).any():
        raise ValueError(f"{mesh.path}: all geometry is behind the camera")
    texture = resolve_texture(mesh, options, warn) if inputs.uv is not None else None

    start = time.perf_counter()
    uv = None if inputs.uv is None else inputs.attrs[..., inputs.uv]
    methods = choose_methods(mesh, faces, uv, clip, show, options, settings)
    try:
        frame = rasterize_quads(clip, inputs.attrs, options.width, options.height, method=methods,
                                cull_backfaces=options.cull)
    except OverBudget as err:  # over the rasterizer's fragment budget: say which mesh
        raise OverBudget(f"{mesh.path}: {err}") from None
    seconds = time.perf_counter() - start
    covered = frame.face >= 0
    if not covered.any():
        warn(f"{mesh.path}: nothing is in view (try --camera)")
    direction = np.subtract(camera.eye, camera.target)
    image = shade(frame.attrs, covered, inputs, show, texture, direction / np.linalg.norm(direction))
    tinted = image.copy()
    routed = mvc_pixels(frame.face, methods)
    tinted[routed] = 0.55 * image[routed] + 0.45 * OVERLAY_TINT
    return RenderResult(mesh, tinted if options.overlay else image, frame, faces, methods, options.method, seconds,
                        camera, clip, inputs, tinted, settings)
