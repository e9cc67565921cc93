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

import numpy as np

from ..mesh import Mesh
from .framing import camera_for
from .quads import render_corners
from .routing import MVC, SPLIT, route_by_view
from .shading import OVERLAY_TINT, shade, shading_inputs


@dataclass
class RenderOptions:
    """How to render: see ``affinity render --help`` for each option's meaning."""

    method: str = "hybrid"
    route: str = "view"
    pixel_tolerance: float = 0.5
    width: int = 800
    height: int = 600
    camera: tuple | None = None
    up: str | None = None
    show: str | None = None
    texture: str | np.ndarray | None = None  # an image path, or an (h, w, 3) float RGB image
    overlay: bool = False
    cull: bool = False


@dataclass
class RenderResult:
    """A finished render.

    Attributes
    ----------
    image : (H, W, 3) float32 RGB in [0, 1]
    frame : render.Frame, ``face`` indexes the render quads
    faces : (R,) int64, the mesh face of each render quad
    methods : (R,) str, the method each render quad was drawn with
    """

    mesh: Mesh
    image: np.ndarray
    frame: object
    faces: np.ndarray
    methods: np.ndarray
    method: str
    seconds: float

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


def default_show(mesh: Mesh) -> str:
    if mesh.texcoords is not None:
        return "uv"
    return "color" if mesh.colors is not None else "shaded"


def uv_routing_inputs(mesh: Mesh, faces: np.ndarray, uv: np.ndarray):
    """The view-independent part of routing by view (``affinity.draw.routing``), once per mesh:
    the split's texture displacement of every render quad, and the lint's uv error
    (along 0-2, uv units) per render quad when some uv quad is degenerate, else None."""
    from .routing import uv_displacement

    moves = uv_displacement(uv)
    uv_error = None
    if moves.degenerate.any():
        from ..lint import quad_uv_error

        quad_faces, error = quad_uv_error(mesh, diagonal="02")
        per_face = np.zeros(mesh.n_faces)
        per_face[quad_faces] = np.nan_to_num(error)
        uv_error = per_face[faces]
    return moves, uv_error


def choose_methods(mesh: Mesh, faces: np.ndarray, uv: np.ndarray | None, clip: np.ndarray,
                   show: str, options: RenderOptions) -> np.ndarray:
    """The method of every render quad: one name, or the hybrid's per-quad routing.

    ``uv`` (R, 4, 2) is the render quads' texture coordinates when the render
    shows them, else None. Routing by view projects the split's largest texture
    displacement (along the renderer's diagonal 0-2) to pixels; for colours and
    normals, and with ``--route lint``, the lint rule of the attribute shown decides.
    """
    if options.method != "hybrid":
        return np.full(len(faces), options.method)
    routes_uv = uv is not None
    if options.route == "view" and routes_uv:
        moves, uv_error = uv_routing_inputs(mesh, faces, uv)
        return route_by_view(moves, uv, clip, options.width, options.height,
                             options.pixel_tolerance, options.cull, uv_error)
    from ..lint import lint_mesh, scored_code_of
    from ..settings import Settings

    code = scored_code_of("uv" if routes_uv else ("color" if show == "color" else "normal"))
    flagged = np.zeros(mesh.n_faces, dtype=bool)
    for hits in lint_mesh(mesh, Settings(select=[code], diagonal="02")):
        flagged[hits.faces] = True
    return np.where(flagged[faces], MVC, SPLIT)


def resolve_texture(mesh: Mesh, options: RenderOptions, warn: Callable[[str], None]) -> np.ndarray:
    """The explicit texture (an image, or a path whose errors are fatal), else map_Kd (a missing
    one warns), else the checker."""
    from .texture import TextureError, checker, load_image

    if isinstance(options.texture, np.ndarray):
        return options.texture
    if options.texture:
        return load_image(options.texture)
    path = mesh.texture_path()
    if path:
        try:
            return load_image(path)
        except TextureError as err:
            warn(f"{err}; using the checker texture")
    return checker()


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

    from ..loaders import load
    from ..scenes import DEMO_SPHERE

    if source is None:
        mesh, view = DEMO_SPHERE.mesh(), DEMO_SPHERE.view
        options = replace(options, camera=options.camera or view.camera, up=options.up or view.up)
    else:
        mesh = load(source) if isinstance(source, (str, os.PathLike)) else source
    if mesh.n_faces == 0:
        raise ValueError(f"{mesh.path}: the mesh has no faces to render")
    show = options.show or default_show(mesh)
    faces, corners = render_corners(mesh)
    inputs = shading_inputs(mesh, corners, show)
    camera = camera_for(mesh, options.width, options.height, options.camera, options.up)
    clip = to_clip(mesh.positions, camera.matrix)[mesh.corner_vertex[corners]]
    if not (clip[..., 3] > 0).any():
        raise ValueError(f"{mesh.path}: all geometry is behind the camera")
    texture = resolve_texture(mesh, options, warn) if inputs.uv is not None else None

    start = time.perf_counter()
    uv = None if inputs.uv is None else inputs.attrs[..., inputs.uv]
    methods = choose_methods(mesh, faces, uv, clip, show, options)
    frame = rasterize_quads(clip, inputs.attrs, options.width, options.height, method=methods,
                            cull_backfaces=options.cull)
    seconds = time.perf_counter() - start
    covered = frame.face >= 0
    if not covered.any():
        warn(f"{mesh.path}: nothing is in view (try --camera)")
    direction = np.subtract(camera.eye, camera.target)
    image = shade(frame.attrs, covered, inputs, show, texture, direction / np.linalg.norm(direction))
    if options.overlay:
        routed = covered & (methods[np.maximum(frame.face, 0)] == MVC)
        image[routed] = 0.55 * image[routed] + 0.45 * OVERLAY_TINT
    return RenderResult(mesh, image, frame, faces, methods, options.method, seconds)
