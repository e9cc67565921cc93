"""The up-axis guess on z-up exports: a vehicle lying on its wheels, a heightfield terrain; y-up ones stay y."""

from __future__ import annotations

import numpy as np
from helpers.cli import run

from affinity.loaders import load
from affinity.mesh import mesh_from_polygons


def terrain(n: int = 20, up: str = "z"):
    """An n x n rolling heightfield (closed-form heights), up along ``up``."""
    xs, ys = np.meshgrid(np.linspace(0, 10, n + 1), np.linspace(0, 10, n + 1))
    heights = 0.4 * np.sin(xs) * np.cos(0.7 * ys)
    points = np.stack([xs.ravel(), ys.ravel(), heights.ravel()], axis=1)
    if up == "y":
        points = points[:, [0, 2, 1]]
    row, col = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    first = (row * (n + 1) + col).ravel()
    quads = np.stack([first, first + 1, first + n + 2, first + n + 1], axis=1)
    return mesh_from_polygons("terrain", points[quads].reshape(-1, 3), np.arange(4 * n * n).reshape(-1, 4))


def test_a_heightfield_terrain_is_up_along_its_height():
    from affinity.draw.framing import guess_up_axis

    assert guess_up_axis(terrain(up="z")) == "z"
    assert guess_up_axis(terrain(up="y")) == "y"


def test_the_car_lies_on_z_and_the_figure_stands_on_y(shared_meshes):
    from affinity.draw.framing import guess_up_axis

    assert guess_up_axis(load(str(shared_meshes / "osd_catmark_car.obj"))) == "z"
    assert guess_up_axis(load(str(shared_meshes / "makehuman_base_hm08.obj"))) == "y"
    assert guess_up_axis(load(str(shared_meshes / "spot_control_mesh.obj"))) == "y"


def test_help_says_the_default_guesses():
    for command in ("render", "report"):
        done = run(command, "--help")
        assert "guessed" in " ".join(done.stdout.split()), command
