"""One scene of the study: every method and hybrid setting, timed together and compared with ``exact``.

Configurations of a scene (all drawn by ``render.rasterize_quads`` on the same
clip-space quads, at the same size):

- the methods ``split``, ``mvc``, ``bilinear``, ``projective`` and the
  reference ``exact``; ``split-13``, the split along the other diagonal (the
  quads' corners renumbered 1, 2, 3, 0), for the diagonal dependence;
- the hybrid routed by view (uv only) at every pixel tolerance: a quad goes to
  mvc when the split's largest texture displacement, projected to pixels, exceeds the tolerance
  (``affinity.draw.routing``);
- the hybrid routed by the lint (with ``lint_route``, and always for colours,
  which the hybrid routes by the lint): a quad goes to mvc when its rule value
  exceeds the threshold, in the error reading and, for uv, in the
  paper's barycentric reading.

A hybrid's time includes its per-frame routing decision; the per-mesh measure
it routes on (the uv displacement or lint values, computed once per asset) is timed
once, as ``setup_s``. Errors are in the lint's units of the attribute shown
(texels of a ``texture_size`` texture for uv, 1/255 steps for colours); uv
errors are also given in screen pixels (``px_*``: texels over the exact
render's local texels per pixel), the unit of the hybrid's pixel tolerance.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..attributes import Attribute, attribute_named
from ..mesh import Mesh
from ..scenes import Scene
from ..settings import Settings
from .metrics import crease, error_summary, psnr, ssim, texels_per_pixel
from .timing import time_interleaved

PLAIN_METHODS = ("split", "split-13", "mvc", "bilinear", "projective", "exact")
#: Rows that compete on the Pareto front (exact is the reference, split-13 the other diagonal).
CANDIDATES = frozenset({"split", "mvc", "bilinear", "projective", "hybrid"})
ROTATED = [1, 2, 3, 0]

COLUMNS = (
    "scene", "source", "quads", "width", "height", "method", "route", "setting", "to_mvc",
    "seconds", "seconds_min", "seconds_max", "repeats", "setup_s", "fragments", "mfragments_per_s",
    "unit", "compared_pixels", "err_rms", "err_p99", "err_max", "px_rms", "px_p99", "px_max", "psnr_db", "ssim",
    "crease_mean", "crease_max", "crease_quads", "diagonal_rms", "pareto",
)


@dataclass(frozen=True)
class StudySettings:
    """What to measure: image size, repeats, the hybrid's settings to sweep, the texel unit."""

    width: int = 800
    height: int = 600
    repeat: int = 7
    warmup: int = 1
    tolerances: tuple = (0.03, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0)
    lint_route: bool = False
    misplacement_thresholds: tuple = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0)
    barycentric_thresholds: tuple = (0.001, 0.003, 0.01, 0.03, 0.1, 0.3)
    texture_size: int = 1024


QUICK = StudySettings(width=240, height=180, repeat=2, tolerances=(0.1, 0.5, 2.0),
                      misplacement_thresholds=(0.5, 4.0), barycentric_thresholds=(0.01, 0.1))


@dataclass
class PreparedScene:
    """A case ready to draw.

    ``faces`` (R,) the mesh face of each render quad; ``clip`` (R, 4, 4);
    ``inputs`` the attributes drawn (``affinity.draw.shading.ShadingInputs``);
    ``show`` the attribute shown, as the command line names it (``"uv"``, ``"color"``);
    ``code`` the scored rule of that attribute (the rule registry's, e.g. uv's uv-disaffine);
    ``lint`` the Settings governing the mesh's file (``affinity.config.file_settings``);
    ``routes`` maps a hybrid route name to (its per-render-quad values (R,), for
    ``"view"`` the ``affinity.draw.drawing.uv_routing_inputs``,
    the settings to sweep, the seconds the values took to compute).
    """

    case: Scene
    mesh: Mesh
    faces: np.ndarray
    clip: np.ndarray
    inputs: object
    show: str
    code: str
    texture: np.ndarray | None
    light: np.ndarray
    lint: Settings
    routes: dict = field(default_factory=dict)

    @property
    def attribute(self) -> Attribute:
        """The attribute shown, from the attribute registry: its field, unit and label."""
        return attribute_named(self.show)

    @property
    def columns(self) -> slice:
        """The attribute columns compared (``ShadingInputs`` names them as the attribute is named)."""
        return getattr(self.inputs, self.attribute.name)


@dataclass
class Config:
    """One thing to draw: a method, or the hybrid with a route and a setting."""

    method: str
    draw: Callable[[], object]
    clip: np.ndarray
    route: str = ""
    setting: float = np.nan
    to_mvc: float = np.nan
    setup_s: float = np.nan


def prepare(case: Scene, settings: StudySettings) -> PreparedScene:
    """Load, frame and convert a case (one split render gives the render quads, their clip corners and
    attributes); compute the per-quad measures the hybrid routes on.

    Raises ValueError for a mesh without faces, or with neither uv nor vertex colours (nothing to compare).
    """
    from ..attributes import drawn_attribute
    from ..draw.drawing import RenderOptions, render_mesh
    from ..draw.texture import checker
    from ..lint import scored_codes

    mesh = case.mesh()
    if mesh.n_faces == 0:
        raise ValueError(f"{case.name}: the mesh has no faces")
    show = drawn_attribute(mesh)
    if show == "shaded":
        raise ValueError(f"{case.name}: no texture coordinates or vertex colours to compare")
    texture = checker(settings.texture_size) if show == "uv" else None
    drawn = render_mesh(mesh, RenderOptions(method="split", show=show, width=settings.width, height=settings.height,
                                            camera=case.view.camera, up=case.view.up, texture=texture))
    direction = np.subtract(drawn.camera.eye, drawn.camera.target)
    scene = PreparedScene(case, mesh, drawn.faces, drawn.clip, drawn.inputs, show, scored_codes(mesh, show)[0],
                          texture, direction / np.linalg.norm(direction), drawn.settings)
    scene.routes = _routes(scene, settings)
    return scene


def _routes(scene: PreparedScene, settings: StudySettings) -> dict:
    """Route name -> (values per render quad, settings to sweep, seconds to compute the values).

    The lint runs with the settings governing the mesh's file (defaults for a built-in scene), in the
    reading swept, along 0-2 and with the study's texture size.
    """
    from dataclasses import replace

    from ..draw.drawing import uv_routing_inputs
    from ..lint import quad_scores
    from ..rules import RULES

    routes = {}
    if scene.show == "uv":
        start = time.perf_counter()
        inputs = uv_routing_inputs(scene.mesh, scene.faces, scene.inputs.attrs[..., scene.inputs.uv], scene.lint)
        routes["view"] = (inputs, settings.tolerances, time.perf_counter() - start)
    readings = [("error", settings.misplacement_thresholds)]
    if "barycentric" in RULES[scene.code].readings:  # the paper's score: a reading of the uv rule only
        readings.append(("barycentric", settings.barycentric_thresholds))
    if settings.lint_route or scene.show != "uv":
        for measure, thresholds in readings:
            start = time.perf_counter()
            lint = replace(scene.lint, measure=measure, diagonal="02", texture_size=settings.texture_size)
            scores = quad_scores(scene.mesh, lint, scene.code)
            routes[f"lint {measure}"] = (_per_render_quad(scene, scores.faces, scores.values), thresholds,
                                         time.perf_counter() - start)
    return routes


def _per_render_quad(scene: PreparedScene, faces: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Values given for some mesh faces, spread to the render quads (0 for faces not listed)."""
    per_face = np.zeros(scene.mesh.n_faces)
    per_face[faces] = values
    return per_face[scene.faces]


def configurations(scene: PreparedScene, settings: StudySettings) -> list[Config]:
    """Everything drawn for a scene: the plain methods, then each hybrid route at each setting."""
    from render import rasterize_quads

    from ..draw.routing import MVC

    attrs, width, height = scene.inputs.attrs, settings.width, settings.height
    rotated = (scene.clip[:, ROTATED], attrs[:, ROTATED])

    def plain(method):
        clip, values = rotated if method == "split-13" else (scene.clip, attrs)
        name = "split" if method == "split-13" else method
        return Config(method, lambda: rasterize_quads(clip, values, width, height, name), clip)

    configs = [plain(method) for method in PLAIN_METHODS]
    for route, (values, sweep, setup_s) in scene.routes.items():
        for setting in sweep:
            choose = _chooser(scene, route, values, float(setting), width, height)
            configs.append(Config("hybrid", lambda choose=choose: rasterize_quads(scene.clip, attrs, width, height,
                                                                                    choose()),
                                  scene.clip, route, float(setting), float(np.mean(choose() == MVC)), setup_s))
    return configs


def _chooser(scene: PreparedScene, route: str, values: np.ndarray, setting: float, width: int, height: int):
    """The hybrid's per-frame decision: a function giving the method of every render quad (R,) str."""
    from ..draw.routing import MVC, SPLIT, route_by_view

    if route == "view":
        uv = scene.inputs.attrs[..., scene.inputs.uv]
        moves, uv_error = values
        return lambda: route_by_view(moves, uv, scene.clip, width, height, setting, uv_error=uv_error)
    return lambda: np.where(values > setting, MVC, SPLIT)


def study_scene(scene: PreparedScene, settings: StudySettings) -> list[dict]:
    """Time every configuration (interleaved) and compare each with exact: one row (``COLUMNS``) each."""
    from ..draw.shading import shade

    configs = configurations(scene, settings)
    timings = time_interleaved([config.draw for config in configs], settings.repeat, settings.warmup)
    frames = {config.method: timing.result for config, timing in zip(configs, timings) if not config.route}
    exact = frames["exact"]

    def image(frame):
        return shade(frame.attrs, frame.face >= 0, scene.inputs, scene.show, scene.texture, scene.light)

    exact_image = image(exact)
    density = (texels_per_pixel(exact.attrs[..., scene.columns], exact.face, settings.texture_size)
               if scene.show == "uv" else None)
    rows = []
    for config, timing in zip(configs, timings):
        frame = timing.result
        row = _facts(scene, settings, config, timing)
        row.update(_errors(scene, settings, frame, exact, image(frame), exact_image, config.clip, density))
        if config.method == "split-13":
            row["diagonal_rms"] = error_summary(_compared(scene, settings, frame, frames["split"])[1])["rms"]
        rows.append(row)
    mark_pareto(rows)
    return rows


def _facts(scene, settings, config, timing) -> dict:
    """The row's identity, routing share and timing."""
    fragments = timing.result.fragments
    return {
        "scene": scene.case.name, "source": scene.case.source, "quads": len(scene.faces),
        "width": settings.width, "height": settings.height, "method": config.method, "route": config.route,
        "setting": config.setting,
        "to_mvc": 1.0 if config.method == "mvc" else 0.0 if not config.route else config.to_mvc,
        "seconds": timing.median, "seconds_min": timing.low, "seconds_max": timing.high,
        "repeats": settings.repeat, "setup_s": config.setup_s, "fragments": fragments,
        "mfragments_per_s": fragments / timing.median / 1e6 if timing.median > 0 else np.nan,
        "diagonal_rms": np.nan,
    }


def _compared(scene, settings, frame, reference):
    """Pixels where both show the same quad (H, W) bool and the per-pixel error (N,) of ``frame``
    against ``reference`` there. (Split and the quad-filling methods may show different quads at a
    pixel of a concave or bow-tie quad: that is coverage, not interpolation, and is left out.)"""
    from ..measures import pixel_error

    both = (frame.face >= 0) & (frame.face == reference.face)
    error = pixel_error(frame.attrs[both][:, scene.columns], reference.attrs[both][:, scene.columns],
                        scene.attribute.field, settings.texture_size)
    return both, error


def _errors(scene, settings, frame, exact, image, exact_image, clip, density) -> dict:
    """Attribute error (and, given the texture density (H, W), in screen pixels), PSNR, SSIM
    against exact, and the crease of ``frame``."""
    from ..measures import pixel_error

    both, error = _compared(scene, settings, frame, exact)
    summary = error_summary(error)
    in_pixels = {"rms": np.nan, "p99": np.nan, "max": np.nan}
    if density is not None:
        with np.errstate(divide="ignore", invalid="ignore"):
            pixels = error / density[both]
        in_pixels = error_summary(pixels[np.isfinite(pixels)])
    jump, pixels = crease(frame.attrs[..., scene.columns], frame.face, clip)
    fitted = ~np.isnan(jump).any(axis=1)
    size = pixel_error(jump[fitted], np.zeros_like(jump[fitted]), scene.attribute.field, settings.texture_size)
    measured = bool(both.any())
    return {
        "unit": scene.attribute.unit,
        "compared_pixels": int(both.sum()),
        "err_rms": summary["rms"], "err_p99": summary["p99"], "err_max": summary["max"],
        "px_rms": in_pixels["rms"], "px_p99": in_pixels["p99"], "px_max": in_pixels["max"],
        "psnr_db": psnr(image, exact_image, both) if measured else np.nan,
        "ssim": ssim(image, exact_image, both) if measured else np.nan,
        "crease_mean": float(np.average(size, weights=pixels[fitted])) if fitted.any() else np.nan,
        "crease_max": float(size.max()) if fitted.any() else np.nan,
        "crease_quads": int(fitted.sum()),
    }


def mark_pareto(rows: list[dict]) -> None:
    """Set ``pareto`` on every row: True for a candidate no other candidate beats in both time and RMS error.

    Candidates are split, mvc, bilinear, projective and every hybrid setting;
    exact and split-13 get False.
    """
    candidates = [row for row in rows if row["method"] in CANDIDATES]
    time_of = np.array([row["seconds"] for row in candidates])
    error_of = np.array([row["err_rms"] for row in candidates])
    for row in rows:
        row["pareto"] = False
    for k, row in enumerate(candidates):
        no_worse = (time_of <= time_of[k]) & (error_of <= error_of[k])
        better = (time_of < time_of[k]) | (error_of < error_of[k])
        row["pareto"] = not (no_worse & better).any()
