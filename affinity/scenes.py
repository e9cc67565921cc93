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

``DEMO`` lists the scenes bundled as OBJ files under ``affinity/data/demo``;
``python -m affinity.scenes`` rewrites them.
"""

from __future__ import annotations

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


DEMO = {
    "trapezoid.obj": trapezoid,
    "sphere.obj": demo_sphere,
    "color_squares.obj": color_squares,
}


def demo_paths() -> list[str]:
    """Paths of the bundled demo meshes."""
    return [str(DEMO_DIR / name) for name in DEMO]


if __name__ == "__main__":
    from .objwriter import write_obj

    DEMO_DIR.mkdir(parents=True, exist_ok=True)
    for file_name, build in DEMO.items():
        write_obj(build(), DEMO_DIR / file_name, header="quad-affinity demo scene (CC0): " + file_name)
