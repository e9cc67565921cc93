"""Collect what the report shows about each mesh: lint, scores, renders, overview.

Nothing here decides what the page shows; :mod:`affinity.report.sections` does,
from the :class:`MeshResult` collected here. Renders go through
``affinity.draw.render_mesh``, so the pictures are exactly what
``affinity render`` draws.
"""

from __future__ import annotations

import datetime
import os
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..findings import FileReport
from ..lint import QuadScores, quad_scores, scored_codes
from ..mesh import Mesh
from ..settings import Settings
from ..scenes import View
from .demo import MeshInput

RENDER_SIZE = (480, 360)
#: Methods drawn beside the hybrid when it sent quads to mvc (``exact``: the ray / bilinear-patch reference).
COMPARED_METHODS = ("split", "mvc", "exact")


@dataclass(eq=False)
class MeshResult:
    """Everything collected for one input file.

    ``file`` is the lint outcome (with ``error`` or ``skipped`` set, nothing
    else is collected). ``shown`` is the rule code of the attribute the renders
    show (None: plain shading). ``renders`` maps a method (``hybrid`` and, when
    it sent quads to mvc, ``split``, ``mvc``, ``exact``) to its render;
    ``missing`` a method that could not be drawn to the reason. ``overlay`` is
    the hybrid with the mvc quads tinted. ``overview`` is the pyvista picture
    (H, W, 3) uint8, else ``overview_note`` says why there is none.
    """

    input: MeshInput
    file: FileReport
    settings: Settings
    seconds: float = 0.0
    mesh: Mesh | None = None
    scores: dict[str, QuadScores] = field(default_factory=dict)
    shown: str | None = None
    texture: str = ""
    renders: dict = field(default_factory=dict)
    missing: dict[str, str] = field(default_factory=dict)
    render_error: str | None = None
    overlay: object | None = None
    overview: np.ndarray | None = None
    overview_note: str | None = None
    warnings: list[str] = field(default_factory=list)

    @property
    def readable(self) -> bool:
        return self.file.error is None and self.file.skipped is None


@dataclass
class ReportRun:
    """A whole report: one result per input, the settings of the current folder, timing."""

    meshes: list[MeshResult]
    settings: Settings
    started: datetime.datetime
    seconds: float


def _texture_label(mesh: Mesh, view: View) -> str:
    if mesh.texcoords is None:
        return ""
    if view.checks:
        return f"checker texture, {view.checks} squares across"
    from ..loaders.imagesize import image_size

    path = mesh.texture_path()
    if path is None:
        return "checker texture (the mesh names no map_Kd)"
    name = os.path.basename(path)
    return f"texture {name} (map_Kd)" if image_size(path) else f"checker texture (map_Kd {name} is not readable)"


def _render(result: MeshResult, texture: np.ndarray | None, step: Callable[[str], None]) -> None:
    """The hybrid render; when it sent quads to mvc, the compared methods and the overlay too."""
    from ..draw.drawing import RenderOptions, render_mesh
    from ..draw.routing import MVC
    from ..draw.texture import TextureError

    view = result.input.view

    def draw(warn=lambda line: None, **options):
        chosen = RenderOptions(width=RENDER_SIZE[0], height=RENDER_SIZE[1], camera=view.camera, up=view.up,
                               texture=texture, **options)
        return render_mesh(result.mesh, chosen, warn)

    step("render hybrid")
    try:
        hybrid = draw(warn=result.warnings.append, method="hybrid")
    except (ValueError, TextureError) as err:
        result.render_error = str(err)
        return
    result.renders["hybrid"] = hybrid
    if not (hybrid.methods == MVC).any():
        return
    for method in COMPARED_METHODS:
        step(f"render {method}")
        try:
            result.renders[method] = draw(method=method)
        except NotImplementedError as err:
            result.missing[method] = str(err)
    step("render overlay")
    result.overlay = draw(method="hybrid", overlay=True)


def _overview(result: MeshResult, step: Callable[[str], None]) -> None:
    from ..view import INSTALL_HINT, overview_image, pyvista_installed

    if not pyvista_installed():
        result.overview_note = f"pyvista is not installed (the view extra: {INSTALL_HINT})"
        return
    if result.mesh.n_faces == 0:
        result.overview_note = "the mesh has no faces to show"
        return
    step("3-D overview")
    scores = result.scores.get(result.shown)
    view = result.input.view
    try:
        result.overview = overview_image(result.mesh, scores, view.camera, view.up, RENDER_SIZE)
    except RuntimeError as err:  # pyvista's way of saying the off-screen render failed
        result.overview_note = f"pyvista could not render off-screen: {err}"


def collect_mesh(item: MeshInput, settings: Settings, step: Callable[[str], None] = lambda name: None) -> MeshResult:
    """Lint, score, render and picture one mesh; an unreadable file gives a result with ``file.error``."""
    from ..pipeline.check import load_and_check
    from ..draw.texture import checker

    start = time.perf_counter()
    step("lint")
    file, mesh = load_and_check(item.path, settings)
    result = MeshResult(item, file, settings, mesh=mesh)
    if result.readable:
        step("scores")
        result.scores = {code: quad_scores(result.mesh, settings, code) for code in scored_codes(result.mesh)}
        result.shown = next(iter(result.scores), None)  # uv, else colours, else normals
        result.texture = _texture_label(result.mesh, item.view)
        has_uv = result.mesh.texcoords is not None
        _render(result, checker(512, item.view.checks) if item.view.checks and has_uv else None, step)
        _overview(result, step)
    result.seconds = time.perf_counter() - start
    return result


def collect_run(items: list[MeshInput], settings_for: Callable[[str], Settings], settings: Settings,
                progress) -> ReportRun:
    """Collect every input in order.

    ``settings_for(path)`` gives the lint settings of a file (its configuration);
    ``settings`` are the current folder's, for the summary's thresholds.
    ``progress`` is a tqdm bar (possibly disabled): it shows the file and step and
    advances once per file.
    """
    started = datetime.datetime.now().astimezone()
    start = time.perf_counter()
    meshes = []
    for item in items:
        progress.set_description(os.path.basename(item.path), refresh=False)
        meshes.append(collect_mesh(item, settings_for(item.path), progress.set_postfix_str))
        progress.update()
    return ReportRun(meshes, settings, started, time.perf_counter() - start)
