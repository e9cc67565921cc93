"""Collect what the report shows about each mesh: lint, scores, renders, overview.

Nothing here decides what the page shows; :mod:`affinity.report.sections` does,
from the :class:`MeshResult` collected here. Renders go through
``affinity.draw.render_mesh``, so the pictures are exactly what
``affinity render`` draws.
"""

from __future__ import annotations

import datetime
import functools
import os
import threading
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..findings import FileReport
from ..lint import QuadScores, quad_scores, scored_codes
from ..mesh import Mesh
from ..rules import RULES
from ..scenes import View
from ..settings import Settings
from . import MAX_VIEWS, PLACE_FACES, RENDER_SIZE
from .demo import MeshInput

#: Methods drawn beside the hybrid when it sent quads to mvc (``exact``: the ray / bilinear-patch reference).
COMPARED_METHODS = ("split", "mvc", "exact")
#: Side of a close-up picture, pixels.
CLOSEUP_SIZE = 240
#: The overview's pyvista and the charts' matplotlib: about 2 s of imports, done on a thread while the
#: renders run (see :func:`import_in_background`).
SLOW_IMPORTS = ("pyvista.plotting", "matplotlib.figure", "matplotlib.backends.backend_svg")


@functools.cache
def import_in_background(modules: tuple[str, ...]) -> threading.Thread:
    """Start importing ``modules`` on a daemon thread, once per process; the thread, to join before use.

    Imports are mostly Python and the scores and renders they overlap mostly
    NumPy, which lets go of the GIL (the lint is not overlapped: the loader's own
    threads would compete for it). Join before using a module: pyvista's lazy
    attributes would see a half-imported ``pyvista.plotting``. A module that is
    not installed is left to the report's own message.
    """
    import importlib

    def load() -> None:
        for name in modules:
            try:
                importlib.import_module(name)
            except Exception:  # the report's own import says what is wrong
                return

    thread = threading.Thread(target=load, name="affinity-imports", daemon=True)
    thread.start()
    return thread


class StepTimer:
    """Wall time of one mesh's steps, summed by part (``lint``, ``renders``, ``close-ups``, ...).

    ``timer(label, part)`` ends the running step and starts the next, showing
    ``label`` through ``show`` (the progress bar); ``part`` defaults to the label.
    """

    def __init__(self, show: Callable[[str], None]):
        self.show = show
        self.parts: dict[str, float] = {}
        self._part: str | None = None
        self._since = 0.0

    def __call__(self, label: str, part: str | None = None) -> None:
        self.stop()
        self._part, self._since = part or label, time.perf_counter()
        self.show(label)

    def stop(self) -> dict[str, float]:
        """End the running step; the seconds of every part so far."""
        if self._part is not None:
            self.parts[self._part] = self.parts.get(self._part, 0.0) + time.perf_counter() - self._since
            self._part = None
        return self.parts


@dataclass(frozen=True)
class ReportOptions:
    """The render options ``affinity report`` takes (None: the mesh's own or the default).

    ``camera`` and ``up`` replace every mesh's view; ``size`` is the overview and
    render size (width, height); ``texture`` replaces map_Kd and the line pattern;
    ``place_faces`` is the most faces a close-up's place holds.
    """

    up: str | None = None
    size: tuple[int, int] = RENDER_SIZE
    camera: tuple | None = None
    texture: str | None = None
    pixel_tolerance: float = 0.5
    max_views: int = MAX_VIEWS
    place_faces: int = PLACE_FACES


@dataclass(eq=False)
class MeshResult:
    """Everything collected for one input file.

    ``file`` is the lint outcome (with ``error`` or ``skipped`` set, nothing
    else is collected). ``shown`` is the rule code of the attribute the renders
    show: the first scored rule with findings, else the first scored (uv, colours, normals); None: plain
    shading. ``renders`` maps a method (``hybrid`` and, when
    it sent quads to mvc, ``split``, ``mvc``, ``exact``) to its render (the
    hybrid's ``tinted`` image is the overlay of the quads it sent to mvc). ``overview`` is the pyvista picture
    (H, W, 3) uint8, else ``overview_note`` says why there is none. ``camera``
    and ``up`` are the view of the renders and the overview. ``places`` are every
    flagged place, ranked (:func:`affinity.report.places.choose_places` with no
    limit); ``closeups`` the pictures of the first ``options.max_views`` whose place can be seen, ``dropped``
    a line for each place skipped because it covers too few pixels from every side.
    ``stability`` is the scene's :class:`affinity.report.stiffness.SceneStability`.
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
    render_error: str | None = None
    overview: np.ndarray | None = None
    overview_note: str | None = None
    warnings: list[str] = field(default_factory=list)
    options: ReportOptions = ReportOptions()
    camera: tuple | None = None
    up: str | None = None
    places: list = field(default_factory=list)
    closeups: list = field(default_factory=list)
    dropped: list[str] = field(default_factory=list)
    parts: dict[str, float] = field(default_factory=dict)
    stability: object | None = None

    @property
    def readable(self) -> bool:
        return self.file.error is None and self.file.skipped is None


@dataclass
class ReportRun:
    """A whole report: one result per input, the settings of the current folder, timing.

    ``start`` is the ``time.perf_counter()`` of the command's start (the page
    prints the time from it to the page written); ``seconds`` the time of
    collecting, ``parts`` its seconds by part summed over the meshes, with
    ``start-up`` the time before the first mesh. ``fail_on`` is the level the
    verdict is given at, as ``affinity check --fail-on`` gives it.
    """

    meshes: list[MeshResult]
    settings: Settings
    started: datetime.datetime
    seconds: float
    demo: bool = False
    start: float = 0.0
    parts: dict[str, float] = field(default_factory=dict)
    fail_on: str = "error"


def _texture_label(mesh: Mesh, view: View, texture: str | None = None) -> str:
    if mesh.texcoords is None:
        return ""
    if texture:
        return f"texture {os.path.basename(texture)} (--texture)"
    if view.checks:
        return f"checker texture, {view.checks} squares across"
    from ..textures.decode import why_not_decoded

    path = mesh.texture_path()
    if path is None:
        return "checker texture (the mesh names no map_Kd)"
    name, refused = os.path.basename(path), why_not_decoded(path)
    return f"texture {name} (map_Kd)" if refused is None else f"checker texture (map_Kd {name}: {refused})"


def _render(result: MeshResult, texture: np.ndarray | None, step: StepTimer) -> None:
    """The hybrid render; when it sent quads to mvc, the compared methods too."""
    from ..draw.drawing import RenderOptions, render_mesh
    from ..draw.routing import MVC
    from ..draw.texture import TextureError

    size = result.options.size
    # a mesh with uv whose findings are its vertex colours (a terrain) is drawn in its colours, not the checker
    show = "color" if result.shown and RULES[result.shown].attribute == "colors" else None

    def draw(warn=lambda line: None, **options):
        chosen = RenderOptions(width=size[0], height=size[1], camera=result.camera, up=result.up, show=show,
                               texture=texture, pixel_tolerance=result.options.pixel_tolerance, **options)
        return render_mesh(result.mesh, chosen, warn)

    from render.raster import OverBudget

    step("render hybrid", "renders")
    try:
        hybrid = draw(warn=result.warnings.append, method="hybrid")
    except (ValueError, TextureError) as err:
        result.render_error = str(err)
        if isinstance(err, OverBudget):  # pyvista would draw the same stack of faces, for minutes
            result.overview_note = "the mesh is over the renderer's budget (see the render's line)"
        return
    result.renders["hybrid"] = hybrid
    if not (hybrid.methods == MVC).any():
        return
    for method in COMPARED_METHODS:
        step(f"render {method}", "renders")
        result.renders[method] = draw(method=method)


def _overview(result: MeshResult, step: StepTimer) -> None:
    from ..draw.view import INSTALL_HINT, overview_image, pyvista_installed

    if result.overview_note:  # left out already, and why
        return
    if not pyvista_installed():
        result.overview_note = f"pyvista is not installed (the view extra: {INSTALL_HINT})"
        return
    if result.mesh.n_faces == 0:
        result.overview_note = "the mesh has no faces to show"
        return
    step("3-D overview")
    import_in_background(SLOW_IMPORTS).join()
    scores = result.scores.get(result.shown)
    try:
        result.overview = overview_image(result.mesh, scores, result.camera, result.up, result.options.size,
                                         scalar_bar=False)
    except RuntimeError as err:  # pyvista's way of saying the off-screen render failed
        result.overview_note = f"pyvista could not render off-screen: {err}"


def _view(result: MeshResult) -> None:
    """The camera and up axis of the renders and the overview: ``--camera``/``--up``, else the scene's view,
    else the whole mesh from its broad side (:func:`affinity.draw.framing.overview_camera`)."""
    from ..draw.framing import overview_camera, up_axis_of

    options, view = result.options, result.input.view
    result.up = up_axis_of(result.mesh, options.up or view.up)
    result.camera = options.camera or view.camera
    if result.camera is None and result.mesh.n_faces:
        result.camera = overview_camera(result.mesh, *options.size, result.up)


def _closeups(result: MeshResult, step: StepTimer) -> None:
    """Rank every flagged place; draw the first ``max_views`` that share no face with an earlier close-up, whose
    worst face no earlier close-up shows (``Closeup.seen``) and that show no earlier one's defect again
    (:func:`affinity.report.places.repeats`): each close-up a new spot."""
    from ..draw.closeup import face_centroids
    from ..draw.framing import used_points
    from .closeups import closeup
    from .places import choose_places, places_of, repeats

    step("places")
    mesh = result.mesh
    by_rule = {hits.code: places_of(mesh, hits, result.options.place_faces) for hits in result.file.hits}
    result.places = choose_places(by_rule, sum(len(p) for p in by_rule.values()))
    shown = np.zeros(mesh.n_faces, dtype=bool)  # no two close-ups share a face
    seen = np.zeros(mesh.n_faces, dtype=bool)  # nor show one place's worst face again
    centroids = face_centroids(mesh)
    points = used_points(mesh)
    box = (points.min(axis=0), points.max(axis=0)) if len(points) else (np.zeros(3), np.zeros(3))
    for place in result.places:
        if len(result.closeups) == result.options.max_views:
            break
        if (shown[place.faces].any() or seen[place.worst]
                or any(repeats(place, drawn.place, centroids, *box) for drawn in result.closeups)):
            continue
        step(f"close-up {len(result.closeups) + 1}", "close-ups")
        drawn = closeup(mesh, place, result.settings, CLOSEUP_SIZE, result.options.pixel_tolerance,
                        result.options.texture)
        if drawn.dropped:
            result.dropped.append(drawn.dropped)
        else:
            result.closeups.append(drawn)
            shown[place.faces] = True
            seen[drawn.seen] = True


def collect_mesh(item: MeshInput, settings: Settings, step: Callable[[str], None] = lambda name: None,
                 options: ReportOptions = ReportOptions()) -> MeshResult:
    """Lint, score, render and picture one mesh; an unreadable file gives a result with ``file.error``.

    ``step`` is called with each step's name as it starts (the progress bar).
    """
    from ..draw.drawing import over_render_budget
    from ..draw.texture import checker
    from ..pipeline.check import load_and_check

    start = time.perf_counter()
    timer = StepTimer(step)
    timer("lint")
    file, mesh = load_and_check(item.path, settings)
    result = MeshResult(item, file, settings, mesh=mesh, options=options)
    if result.readable:
        timer("scores")
        import_in_background(SLOW_IMPORTS)
        result.scores = {code: quad_scores(result.mesh, settings, code) for code in scored_codes(result.mesh)}
        flagged = {hits.code for hits in file.hits}  # the flagged attribute, else uv, else colours, else normals
        result.shown = next((code for code in result.scores if code in flagged), next(iter(result.scores), None))
        result.texture = _texture_label(result.mesh, item.view, options.texture)
        has_uv = result.mesh.texcoords is not None
        result.render_error = over_render_budget(result.mesh)
        if result.render_error:  # no pictures: framing and drawing it would take gigabytes
            result.overview_note = "the mesh is over the renderer's budget (see the render's line)"
        else:
            _view(result)
            texture = options.texture or (checker(512, item.view.checks) if item.view.checks and has_uv else None)
            _render(result, texture, timer)
            if "hybrid" in result.renders:
                from .stiffness import render_stability

                timer("stability")
                result.stability = render_stability(result.renders["hybrid"])
            _overview(result, timer)
            if result.mesh.n_faces:
                _closeups(result, timer)
    import_in_background(SLOW_IMPORTS).join()  # nothing half-imported is left to the caller
    result.parts = timer.stop()
    result.seconds = time.perf_counter() - start
    return result


def collect_run(items: list[MeshInput], settings_for: Callable[[str], Settings], settings: Settings,
                progress, options: ReportOptions = ReportOptions(), demo: bool = False,
                start: float | None = None, fail_on: str = "error") -> ReportRun:
    """Collect every input in order.

    ``settings_for(path)`` gives the lint settings of a file (its configuration);
    ``settings`` are the current folder's, for the summary's thresholds.
    ``progress`` is a tqdm bar (possibly disabled): it shows the file and step and
    advances once per file. ``demo``: the inputs are the built-in demo scenes.
    ``start`` is the command's ``time.perf_counter()`` at its start (default: now); ``fail_on`` the level of
    the verdict (``--fail-on``).
    """
    started = datetime.datetime.now().astimezone()
    collecting = time.perf_counter()
    start = collecting if start is None else start
    meshes = []
    for item in items:
        progress.set_description(os.path.basename(item.path), refresh=False)
        meshes.append(collect_mesh(item, settings_for(item.path), progress.set_postfix_str, options))
        progress.update()
    parts = Counter({"start-up": collecting - start})
    for result in meshes:
        parts.update(result.parts)  # adds the seconds of each part
    return ReportRun(meshes, settings, started, time.perf_counter() - collecting, demo, start, dict(parts), fail_on)
