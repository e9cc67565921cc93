"""Built-in scenes: the paper's figures rebuilt from their captions, as meshes.

Our own constructions (design.md: the seeds hold only the captions):

- :func:`trapezoid` — Bloomenthal 2022 Fig. 3: a trapezoid carrying a square
  texture, the smallest quad whose split shows the diagonal crease.
- :func:`latlong_sphere` — Fig. 6/9/12/13: a unit sphere with longitude/latitude
  texture coordinates; quads turn into trapezoids toward the poles and the pole
  rows are degenerate quads (two corners at the pole).
- :func:`color_squares` — Fig. 10: two unit squares, one with corner colours
  that do not form a parallelogram in colour space (blue, red, green, black) and
  one whose colours do (blue, red, yellow, cyan).
- :func:`quad_strip` — a twisted, tapering ribbon of nonplanar quads (HT04
  Fig. 10/11, Bloomenthal section 3.4): each quad is a bilinear patch whose uv
  is the patch's own (s, t) scaled, so the exact render is the parametrisation.

``SCENES`` lists every built-in scene once, with its view: the demo meshes
(bundled as OBJ files under ``affinity/data/demo``, rewritten by ``python -m
affinity.scenes``), the study's figures and the tests' scenes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np

from .mesh import Mesh, mesh_from_polygons

DEMO_DIR = Path(__file__).parent / "data" / "demo"


def trapezoid() -> Mesh:
    """One planar trapezoid (bottom 2 wide, top 1 wide, 1.5 high) with unit-square uv."""
    positions = [[-1.0, -0.75, 0.0], [1.0, -0.75, 0.0], [0.5, 0.75, 0.0], [-0.5, 0.75, 0.0]]
    uv = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    return mesh_from_polygons("trapezoid", positions, [[0, 1, 2, 3]], texcoords=uv)


def latlong_sphere(n_lon: int = 16, n_lat: int = 8, dense_poles: bool = False) -> Mesh:
    """A unit sphere (z up) of ``n_lon * n_lat`` quads with equirectangular uv and normals.

    Vertex rows run from the south pole to the north pole; each row, the pole rows
    included, has ``n_lon + 1`` vertices (the seam column is duplicated, the poles
    are ``n_lon + 1`` coincident vertices), so every face is a quad and the pole
    quads have two corners at the pole. ``u = longitude / 2 pi``, ``v`` = row / n_lat.
    With ``dense_poles`` the latitudes are ``pi/2 sin(pi/2 s)`` for evenly spaced s,
    rows denser toward the poles (Bloomenthal Fig. 13).
    """
    s = np.linspace(-1.0, 1.0, n_lat + 1)
    lat = 0.5 * np.pi * (np.sin(0.5 * np.pi * s) if dense_poles else s)
    lon = np.linspace(0.0, 2.0 * np.pi, n_lon + 1)
    lat_grid, lon_grid = np.meshgrid(lat, lon, indexing="ij")
    positions = np.stack(
        [np.cos(lat_grid) * np.cos(lon_grid), np.cos(lat_grid) * np.sin(lon_grid), np.sin(lat_grid)],
        axis=-1,
    ).reshape(-1, 3)
    positions[np.abs(positions) < 1e-15] = 0.0
    u, v = np.meshgrid(np.arange(n_lon + 1) / n_lon, np.arange(n_lat + 1) / n_lat)
    uv = np.stack([u, v], axis=-1).reshape(-1, 2)
    row, col = np.meshgrid(np.arange(n_lat), np.arange(n_lon), indexing="ij")
    first = (row * (n_lon + 1) + col).reshape(-1)
    faces = np.stack([first, first + 1, first + n_lon + 2, first + n_lon + 1], axis=1)
    name = f"latlong_sphere_{n_lon}x{n_lat}" + ("_dense" if dense_poles else "")
    return mesh_from_polygons(name, positions, faces, texcoords=uv, normals=positions)


def color_squares() -> Mesh:
    """Two unit squares side by side; left colours disaffine, right colours affine."""
    positions = np.array(
        [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [1.5, 0, 0], [2.5, 0, 0], [2.5, 1, 0], [1.5, 1, 0]],
        dtype=float,
    )
    blue, red, green, black = [0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 0, 0]
    yellow, cyan = [1, 1, 0], [0, 1, 1]
    colors = [blue, red, green, black, blue, red, yellow, cyan]
    return mesh_from_polygons("color_squares", positions, [[0, 1, 2, 3], [4, 5, 6, 7]], colors=colors)


def quad_strip(n: int = 6, twist: float = 0.35, taper: float = 0.15) -> Mesh:
    """A ribbon of ``n`` nonplanar quads along x in [-2, 2] (y up), with uv on a regular grid.

    The cross-section at x is the segment of half-width ``0.5 + taper * x``
    through the x axis, turned by ``twist * x`` radians about it, so neighbouring
    sections are skew: every quad is a twisted trapezoid, a bilinear patch that
    no plane contains. ``u = i / n`` along the strip, ``v`` 0 and 1 across it.
    """
    x = np.linspace(-2.0, 2.0, n + 1)
    half = 0.5 + taper * x
    angle = twist * x
    side = np.stack([np.zeros_like(x), np.cos(angle), np.sin(angle)], axis=-1) * half[:, None]
    rail = np.stack([x, np.zeros_like(x), np.zeros_like(x)], axis=-1)
    positions = np.concatenate([rail - side, rail + side])  # bottom rail, then top rail
    u = np.arange(n + 1) / n
    uv = np.concatenate([np.stack([u, np.zeros_like(u)], -1), np.stack([u, np.ones_like(u)], -1)])
    i = np.arange(n)
    faces = np.stack([i, i + 1, n + 2 + i, n + 1 + i], axis=1)
    return mesh_from_polygons("quad_strip", positions, faces, texcoords=uv)


def demo_sphere() -> Mesh:
    """The demo sphere: 16 x 8 quads, as coarse as Bloomenthal's Fig. 9."""
    return latlong_sphere(16, 8)


@dataclass(frozen=True)
class View:
    """How a scene is looked at.

    ``camera`` is ``RenderOptions.camera``: (eye, target, vertical field of view
    in degrees), None to frame the whole mesh; ``up`` the world up axis (None:
    the file's, else y). ``checks``: draw the texture as a checker with this many
    squares across instead of the default fine checker.
    """

    camera: tuple | None = None
    up: str | None = None
    checks: int | None = None


@dataclass(frozen=True)
class Scene:
    """A built-in scene: its name, the figure it rebuilds, the mesh, and its view.

    ``file`` names the scene's OBJ under ``affinity/data/demo`` when it is one
    of the demo meshes (``affinity check --demo``, ``affinity report``);
    ``quick`` keeps it in the quick study (``affinity bench --quick``); ``study``
    puts it in the study at all.
    """

    name: str
    source: str
    mesh: Callable[[], Mesh]
    view: View = View()
    file: str | None = None
    study: bool = True
    quick: bool = False


#: Straight on: the image plane is parallel to the trapezoid, every corner has
#: the same w and the picture is the paper's front view. A 12-square checker is
#: coarse enough for the crease along the diagonal to read at 480 pixels.
FRONT_OF_TRAPEZOID = View(((0.0, 0.0, 10.0), (0.0, 0.0, 0.0), 12.0), "y", checks=12)
TILTED_TRAPEZOID = View(((0.9, -2.2, 1.6), (0.0, 0.0, 0.0), 40.0), "z")
#: The lat-long sphere (z up) seen from above the equator, the pole rows in view.
SPHERE_FROM_ABOVE_EQUATOR = View(((0.0, -2.9, 2.1), (0.0, 0.0, 0.05), 40.0), "z")
NORTH_POLE_CLOSE_UP = View(((0.0, -0.75, 1.55), (0.0, 0.0, 0.92), 40.0), "z")
STRIP_IN_PERSPECTIVE = View(((1.2, 1.5, 3.0), (0.0, 0.0, 0.0), 45.0), "y")
FRONT_OF_COLOR_SQUARES = View(((1.25, 0.5, 10.0), (1.25, 0.5, 0.0), 12.0), "y")

#: Every built-in scene, once: the demo meshes, the study's figures, the tests' scenes.
SCENES = (
    Scene("trapezoid front", "Bloomenthal Fig. 3", trapezoid, FRONT_OF_TRAPEZOID, file="trapezoid.obj", quick=True),
    Scene("trapezoid tilted", "Bloomenthal Fig. 3, in perspective", trapezoid, TILTED_TRAPEZOID),
    Scene("sphere 16x8", "Bloomenthal Fig. 9", demo_sphere, SPHERE_FROM_ABOVE_EQUATOR, file="sphere.obj",
          study=False),
    Scene("sphere 8x16", "Bloomenthal Fig. 9", partial(latlong_sphere, 8, 16), SPHERE_FROM_ABOVE_EQUATOR,
          quick=True),
    Scene("sphere 30x20", "Bloomenthal Fig. 12 top", partial(latlong_sphere, 30, 20), SPHERE_FROM_ABOVE_EQUATOR),
    Scene("sphere 100x40", "Bloomenthal Fig. 12 bottom", partial(latlong_sphere, 100, 40),
          SPHERE_FROM_ABOVE_EQUATOR),
    Scene("sphere 100x40 pole", "Bloomenthal Fig. 13 top", partial(latlong_sphere, 100, 40), NORTH_POLE_CLOSE_UP),
    Scene("sphere 100x40 dense poles", "Bloomenthal Fig. 13 bottom",
          partial(latlong_sphere, 100, 40, dense_poles=True), NORTH_POLE_CLOSE_UP),
    Scene("color squares", "Bloomenthal Fig. 10", color_squares, FRONT_OF_COLOR_SQUARES, file="color_squares.obj",
          study=False),
    Scene("quad strip", "nonplanar quads (HT04 Fig. 10)", quad_strip, STRIP_IN_PERSPECTIVE, quick=True),
)

#: The demo scenes bundled as OBJ files, in the order the report shows them.
DEMO_SCENES = tuple(scene for scene in SCENES if scene.file)
#: What ``affinity render`` draws without a mesh.
DEMO_SPHERE = next(scene for scene in SCENES if scene.file == "sphere.obj")


def study_scenes(quick: bool = False) -> list[Scene]:
    """The scenes of the error-against-run-time study; ``quick`` keeps one of each kind."""
    return [scene for scene in SCENES if scene.study and (scene.quick or not quick)]


def demo_paths() -> list[str]:
    """Paths of the bundled demo meshes."""
    return [str(DEMO_DIR / scene.file) for scene in DEMO_SCENES]


if __name__ == "__main__":
    from .loaders.objwriter import write_obj

    DEMO_DIR.mkdir(parents=True, exist_ok=True)
    for scene in DEMO_SCENES:
        write_obj(scene.mesh(), DEMO_DIR / scene.file, header="quad-affinity demo scene (CC0): " + scene.file)
