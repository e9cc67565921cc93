"""The 3-D view (pyvista, the ``view`` extra): the mesh coloured by affinity score, flagged quads outlined.

``affinity view MESH`` opens it in a window; the report renders the same scene
off-screen as its overview picture. pyvista is imported here only, never on
``affinity check``'s path.
"""

from __future__ import annotations

import importlib.util

import numpy as np

from ..attributes import attribute_named
from ..draw import FLAG_COLOUR, UP_AXES, overview_camera, up_axis_of
from ..lint import QuadScores
from ..mesh import Mesh

INSTALL_HINT = "pip install 'quad-affinity[view]'"
SURFACE_GREY = "#d1d5db"


def pyvista_installed() -> bool:
    """Whether the ``view`` extra (pyvista) can be imported."""
    return importlib.util.find_spec("pyvista") is not None


#: Corners of the biggest face VTK gets as a polygon: it triangulates a polygon in quadratic time
#: (8.6 s for one face of 20,000 corners), so a bigger face goes as the fan the renderer draws.
VTK_POLYGON_CORNERS = 64


def polydata(mesh: Mesh):
    """The mesh as a ``pyvista.PolyData``, cell F being face F: every face kept as the polygon it
    is, but for faces of more than :data:`VTK_POLYGON_CORNERS` corners, whose cell is the first
    triangle (corners 0, 1, 2) of their fan, the fan's other triangles appended after the last face.

    VTK's face array is ``[n, v0 .. v(n-1), n, ...]``: each face's corner list
    preceded by its size, built here without a loop over faces.
    """
    import pyvista as pv

    sizes = mesh.face_sizes
    big = sizes > VTK_POLYGON_CORNERS
    counts = np.where(big, 3, sizes)
    first = np.cumsum(counts) - counts
    corner = np.arange(counts.sum()) - np.repeat(first - mesh.face_start[:-1], counts)  # the corners kept
    flat = np.empty(len(corner) + mesh.n_faces, dtype=np.int64)
    markers = first + np.arange(mesh.n_faces)
    is_marker = np.zeros(len(flat), dtype=bool)
    is_marker[markers] = True
    flat[markers] = counts
    flat[~is_marker] = mesh.corner_vertex[corner]
    if big.any():
        faces = np.flatnonzero(big)
        rest = sizes[faces] - 3  # triangles (0, i, i + 1) for i = 2 .. n - 2
        owner = np.repeat(mesh.face_start[faces], rest)
        i = 2 + np.arange(rest.sum()) - np.repeat(np.cumsum(rest) - rest, rest)
        fan = np.stack([np.full(len(i), 3), *(mesh.corner_vertex[owner + k] for k in (0, i, i + 1))], axis=1)
        flat = np.concatenate([flat, fan.ravel()])
    return pv.PolyData(mesh.positions, flat)


def score_range(scores: QuadScores) -> tuple[float, float]:
    """The colour range (low, top) of the scores' log colour scale.

    It spans the scores and a decade either side of the threshold; a log scale
    cannot show 0, so affine quads (score 0 up to rounding) take the lowest colour.
    """
    low = min(scores.threshold / 10, max(float(scores.values.min()), scores.threshold * 1e-3))
    top = max(float(scores.values[np.isfinite(scores.values)].max(initial=low)), scores.threshold * 10)
    return low, top


def build_scene(plotter, mesh: Mesh, scores: QuadScores | None, scalar_bar: bool = True) -> None:
    """Add the mesh to ``plotter``: coloured by ``scores`` (log scale, grey where unscored), flagged quads outlined.

    The colour map and the colour bar's title are the attribute registry's (``Attribute.colormap``,
    ``Attribute.legend``), the bar's unit that of the scores' reading.

    ``scalar_bar`` False leaves the colour bar to the caller (the report draws it beside the picture).
    """
    surface = polydata(mesh)
    if scores is None or len(scores.faces) == 0:
        plotter.add_mesh(surface, color=SURFACE_GREY, show_edges=True, edge_color="#6b7280")
        return
    attribute = attribute_named(scores.attribute)
    low, top = score_range(scores)
    per_face = np.full(surface.n_cells, np.nan)  # the cells past the faces are fans of big faces
    per_face[scores.faces] = np.clip(scores.values, low, top)
    surface.cell_data[scores.unit] = per_face
    plotter.add_mesh(surface, scalars=scores.unit, cmap=attribute.colormap, log_scale=True, clim=(low, top),
                     nan_color=SURFACE_GREY, show_edges=True, edge_color="#374151", show_scalar_bar=scalar_bar,
                     scalar_bar_args={"title": attribute.legend(scores.unit) + "\n", "fmt": "%.2g", "vertical": True,
                                      "position_x": 0.86, "position_y": 0.1, "height": 0.75, "width": 0.06,
                                      "title_font_size": 14, "label_font_size": 12, "color": "#1f2937"})
    flagged = scores.faces[scores.flagged]
    if len(flagged):
        plotter.add_mesh(surface.extract_cells(flagged).extract_all_edges(), color=FLAG_COLOUR, line_width=3)


def place_camera(plotter, mesh: Mesh, camera: tuple | None, up: str | None, size: tuple[int, int]) -> None:
    """``camera`` (eye, target, vertical fov) as in ``RenderOptions``; None frames the whole mesh from its
    broad side with its up axis (``affinity.draw.framing.overview_camera``, the report's view)."""

    up = up_axis_of(mesh, up)
    eye, target, fov = camera or overview_camera(mesh, size[0], size[1], up)
    plotter.camera_position = [tuple(eye), tuple(target), UP_AXES[up]]
    plotter.camera.view_angle = fov


def overview_image(mesh: Mesh, scores: QuadScores | None, camera: tuple | None, up: str | None,
                   size: tuple[int, int], scalar_bar: bool = True) -> np.ndarray:
    """The scene rendered off-screen: (H, W, 3) uint8."""
    import pyvista as pv

    pv.vtk_verbosity("off")  # VTK logs to stderr when it falls back from X to an off-screen context
    plotter = pv.Plotter(off_screen=True, window_size=list(size))
    try:
        plotter.set_background("white")
        build_scene(plotter, mesh, scores, scalar_bar)
        place_camera(plotter, mesh, camera, up, size)
        return np.asarray(plotter.screenshot(return_img=True))[..., :3]
    finally:
        plotter.close()


def show(mesh: Mesh, scores: QuadScores | None, up: str | None) -> None:
    """Open the interactive window (blocks until it is closed)."""
    import pyvista as pv

    plotter = pv.Plotter(title=f"affinity view: {mesh.path}")
    plotter.set_background("white")
    build_scene(plotter, mesh, scores)
    place_camera(plotter, mesh, None, up, tuple(plotter.window_size))
    plotter.show()
