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
from dataclasses import dataclass, field, replace

import numpy as np

from ..attributes import drawn_attribute
from ..findings import FileReport
from ..lint import QuadScores
from ..mesh import Mesh
from ..rules import RULES
from ..scenes import View
from ..settings import Settings
from . import MAX_VIEWS, PLACE_FACES, RENDER_SIZE
from .demo import MeshInput

#: Methods drawn beside the hybrid when it sent quads to mvc (``exact``: the ray / bilinear-patch reference).
COMPARED_METHODS = ("split", "mvc", "exact")
#: Why a mesh over the renderer's budget has no overview (pyvista would draw the same stack of faces, for minutes).
OVER_BUDGET = "the mesh is over the renderer's budget (see the render's line)"
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


@dataclass(frozen=True, eq=False)
class MeshResult:
    """Everything collected for one input file, assembled once by :func:`collect_mesh`.

    ``file`` is the lint outcome (with ``error`` or ``skipped`` set, nothing
    else is collected). ``scores`` are every quad's scores of each scored rule the mesh has an attribute
    for, from that same lint. ``shown`` is the rule code whose attribute the renders show: the first scored
    rule with findings, else the first scored (uv, colours, normals); None: plain shading (what is drawn:
    :attr:`drawn`). ``renders`` maps a method (``hybrid`` and, when
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
    texture: str = ""
    shown: str | None = None
    renders: dict = field(default_factory=dict)
    render_error: str | None = None
    overview: np.ndarray | None = None
    overview_note: str | None = None
    warnings: tuple[str, ...] = ()
    options: ReportOptions = ReportOptions()
    camera: tuple | None = None
    up: str | None = None
    places: tuple = ()
    closeups: tuple = ()
    dropped: tuple[str, ...] = ()
    parts: dict[str, float] = field(default_factory=dict)
    stability: object | None = None

    @property
    def readable(self) -> bool:
        return self.file.error is None and self.file.skipped is None

    @property
    def scores(self) -> dict[str, QuadScores]:
        """Every quad's scores of each scored rule the mesh has an attribute for, from the one lint
        (:attr:`FileReport.scores`)."""
        return self.file.scores

    @property
    def drawn(self) -> str:
        """What the renders draw (:func:`affinity.attributes.drawn_attribute`): ``"uv"``, ``"color"`` or
        ``"shaded"``; the attribute of the rule shown when it is drawable."""
        return drawn_for(self.mesh, self.shown)


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
    from ..draw import painted_texture
    from ..textures.decode import why_not_decoded

    path = painted_texture(mesh)
    if path is None:
        return "checker texture (the mesh names no map_Kd)"
    name, refused = os.path.basename(path), why_not_decoded(path)
    return f"texture {name} (map_Kd)" if refused is None else f"checker texture (map_Kd {name}: {refused})"


@dataclass(frozen=True)
class Renders:
    """What :func:`render_views` drew: ``renders`` method -> RenderResult, ``error`` why there is no render
    (None: the hybrid was drawn), ``over_budget`` whether that is the renderer's budget (the overview would
    draw the same stack of faces, for minutes), ``warnings`` the hybrid's lines (a missing map_Kd, ...)."""

    renders: dict
    error: str | None = None
    over_budget: bool = False
    warnings: tuple[str, ...] = ()


def render_views(mesh: Mesh, drawn: str, view: tuple[tuple | None, str], options: ReportOptions,
                 settings: Settings, texture: str | np.ndarray | None, step: StepTimer) -> Renders:
    """The hybrid render of ``mesh`` showing ``drawn`` from ``view`` (camera, up), routed by ``settings`` (the
    report's, resolved once); when it sent quads to mvc, the compared methods too."""
    from render.raster import OverBudget

    from ..draw import MVC, RenderOptions, TextureError, render_mesh

    camera, up = view

    def draw(warn=lambda line: None, **chosen):
        return render_mesh(mesh, RenderOptions(width=options.size[0], height=options.size[1], camera=camera, up=up,
                                               show=drawn, texture=texture, pixel_tolerance=options.pixel_tolerance,
                                               settings=settings, **chosen), warn)

    step("render hybrid", "renders")
    warnings: list[str] = []
    try:
        hybrid = draw(warn=warnings.append, method="hybrid")
    except (ValueError, TextureError) as err:
        return Renders({}, str(err), isinstance(err, OverBudget), tuple(warnings))
    renders = {"hybrid": hybrid}
    if (hybrid.methods == MVC).any():
        for method in COMPARED_METHODS:
            step(f"render {method}", "renders")
            renders[method] = draw(method=method)
    return Renders(renders, warnings=tuple(warnings))


def overview_picture(mesh: Mesh, scores: QuadScores | None, view: tuple[tuple | None, str], size: tuple[int, int],
                     step: StepTimer) -> tuple[np.ndarray | None, str | None]:
    """The pyvista overview of ``mesh`` coloured by ``scores`` from ``view`` (camera, up): the picture, or None
    and why there is none."""
    from ..view import INSTALL_HINT, overview_image, pyvista_installed

    if not pyvista_installed():
        return None, f"pyvista is not installed (the view extra: {INSTALL_HINT})"
    if mesh.n_faces == 0:
        return None, "the mesh has no faces to show"
    step("3-D overview")
    import_in_background(SLOW_IMPORTS).join()
    try:
        return overview_image(mesh, scores, *view, size, scalar_bar=False), None
    except RuntimeError as err:  # pyvista's way of saying the off-screen render failed
        return None, f"pyvista could not render off-screen: {err}"


def view_of(mesh: Mesh, scene: View, options: ReportOptions) -> tuple[tuple | None, str]:
    """The camera and up axis of the renders and the overview: ``--camera``/``--up``, else the scene's view,
    else the whole mesh from its broad side (:func:`affinity.draw.overview_camera`)."""
    from ..draw import overview_camera, up_axis_of

    up = up_axis_of(mesh, options.up or scene.up)
    camera = options.camera or scene.camera
    if camera is None and mesh.n_faces:
        camera = overview_camera(mesh, *options.size, up)
    return camera, up


def draw_closeups(mesh: Mesh, hits: list, settings: Settings, options: ReportOptions,
                  step: StepTimer) -> tuple[tuple, tuple, tuple[str, ...]]:
    """Every flagged place ranked, the close-ups drawn and the lines for the places dropped.

    The first ``max_views`` places are drawn that share no face with an earlier close-up, whose worst face no
    earlier close-up shows (``Closeup.seen``) and that show no earlier one's defect again
    (:func:`affinity.report.places.repeats`): each close-up a new spot."""
    from ..draw import closeup, face_centroids, used_points
    from .places import choose_places, places_of, repeats

    step("places")
    by_rule = {found.code: places_of(mesh, found, options.place_faces) for found in hits}
    places = choose_places(by_rule, sum(len(p) for p in by_rule.values()))
    closeups, dropped = [], []
    shown = np.zeros(mesh.n_faces, dtype=bool)  # no two close-ups share a face
    seen = np.zeros(mesh.n_faces, dtype=bool)  # nor show one place's worst face again
    centroids = face_centroids(mesh)
    points = used_points(mesh)
    box = (points.min(axis=0), points.max(axis=0)) if len(points) else (np.zeros(3), np.zeros(3))
    for place in places:
        if len(closeups) == options.max_views:
            break
        if (shown[place.faces].any() or seen[place.worst]
                or any(repeats(place, drawn.place, centroids, *box) for drawn in closeups)):
            continue
        step(f"close-up {len(closeups) + 1}", "close-ups")
        drawn = closeup(mesh, place, settings, pixel_tolerance=options.pixel_tolerance, texture=options.texture)
        if drawn.dropped:
            dropped.append(drawn.dropped)
        else:
            closeups.append(drawn)
            shown[place.faces] = True
            seen[drawn.seen] = True
    return tuple(places), tuple(closeups), tuple(dropped)


def shown_code(file: FileReport, scores: dict[str, QuadScores]) -> str | None:
    """The scored rule whose attribute the renders show: the first with findings, else the first the mesh has
    (uv, else colours, else normals); None when the mesh has none."""
    flagged = {hits.code for hits in file.hits}
    return next((code for code in scores if code in flagged), next(iter(scores), None))


def drawn_for(mesh: Mesh, shown: str | None) -> str:
    """What the renders of ``mesh`` draw when they show the scored rule ``shown`` (None: none): its attribute
    when a picture can draw it, else uv, else colours, else shading (:func:`affinity.attributes.drawn_attribute`)."""
    return drawn_attribute(mesh, RULES[shown].attribute if shown else None)


def collect_mesh(item: MeshInput, settings: Settings, step: Callable[[str], None] = lambda name: None,
                 options: ReportOptions = ReportOptions()) -> MeshResult:
    """Lint (once, with every quad's scores), render and picture one mesh; an unreadable file gives a result
    with ``file.error``. ``settings`` govern the lint and every render's routing.

    ``step`` is called with each step's name as it starts (the progress bar).
    """
    from ..pipeline.check import load_and_check

    start = time.perf_counter()
    timer = StepTimer(step)
    timer("lint")
    file, mesh = load_and_check(item.path, settings, scores=True)
    found = {}
    if file.error is None and file.skipped is None:
        import_in_background(SLOW_IMPORTS)
        found = _collect_pictures(item, file, mesh, settings, options, timer)
    import_in_background(SLOW_IMPORTS).join()  # nothing half-imported is left to the caller
    parts = timer.stop()
    return MeshResult(item, file, settings, time.perf_counter() - start, mesh, options=options, parts=parts, **found)


def _collect_pictures(item: MeshInput, file: FileReport, mesh: Mesh, settings: Settings, options: ReportOptions,
                      timer: StepTimer) -> dict:
    """The fields of a readable mesh's :class:`MeshResult` after its lint: what is shown, the renders, the
    stability of the hybrid, the overview and the close-ups, each step computed from the ones before it."""
    from ..draw import checker, over_render_budget

    shown = shown_code(file, file.scores)
    found = {"shown": shown, "texture": _texture_label(mesh, item.view, options.texture)}
    problem = over_render_budget(mesh)
    if problem:  # no pictures: framing and drawing it would take gigabytes
        return {**found, "render_error": problem,
                "overview_note": OVER_BUDGET}
    view = view_of(mesh, item.view, options)
    checks = item.view.checks and mesh.texcoords is not None
    texture = options.texture or (checker(512, item.view.checks) if checks else None)
    drawn = drawn_for(mesh, shown)
    rendered = render_views(mesh, drawn, view, options, settings, texture, timer)
    stability = None
    if "hybrid" in rendered.renders:
        from .stiffness import render_stability

        timer("stability")
        stability = render_stability(rendered.renders["hybrid"])
    if rendered.over_budget:
        overview, note = None, OVER_BUDGET
    else:
        overview, note = overview_picture(mesh, file.scores.get(shown), view, options.size, timer)
    places, closeups, dropped = draw_closeups(mesh, file.hits, settings, options, timer) if mesh.n_faces else (
        (), (), ())
    return {**found, "renders": rendered.renders, "render_error": rendered.error, "warnings": rendered.warnings,
            "camera": view[0], "up": view[1], "stability": stability, "overview": overview, "overview_note": note,
            "places": places, "closeups": closeups, "dropped": dropped}


def _one_report_per_authored_mesh(meshes: list[MeshResult]) -> list[MeshResult]:
    """The results with each authored USD mesh's findings in one of them, as ``affinity check`` reports a run
    (:func:`affinity.pipeline.authored.one_report_per_authored_mesh`); the pictures stay as drawn."""
    from ..pipeline.authored import one_report_per_authored_mesh

    files = one_report_per_authored_mesh([result.file for result in meshes])
    return [result if file is result.file else replace(result, file=file) for result, file in zip(meshes, files)]


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
    meshes = _one_report_per_authored_mesh(meshes)
    parts = Counter({"start-up": collecting - start})
    for result in meshes:
        parts.update(result.parts)  # adds the seconds of each part
    return ReportRun(meshes, settings, started, time.perf_counter() - collecting, demo, start, dict(parts), fail_on)
