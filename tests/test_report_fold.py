"""Close-ups of a fold (Q202) draw the surface shaded, lit across the fold, with the split's diagonal: the split's
two triangles differ in brightness by a visible step across the diagonal, the exact patch does not step there.
Decoded from the panels (the synthetic fold) and from the page's own PNGs (the shared meshes)."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.cli import run
from helpers.closeup_panels import Closeups, decode_panel
from helpers.corpus import SHARED_MESHES

from affinity.draw.closeup import DIAGONAL_INK
from affinity.draw.shading import FLAG_COLOUR
from affinity.loaders.objwriter import write_obj
from affinity.mesh import mesh_from_polygons
from affinity.rules import RULES

pytestmark = pytest.mark.slow  # reports of shared meshes

FOLD_RULES = tuple(code for code, rule in RULES.items() if rule.folding)
#: A step of this many 1/255 is plainly visible (the uv and colour rules' visibility threshold).
VISIBLE_STEP = 8
#: Pixels either side of the diagonal where the brightness is compared.
OFFSET = 3


def step_across_diagonal(panel: np.ndarray) -> tuple[float, int]:
    """The median brightness step (0-255) across the drawn diagonal of ``panel`` (H, W, 3) int: for each
    diagonal pixel, the pixels ``OFFSET`` either side along the normal of the diagonal pixels' principal line,
    where both show the surface (not the diagonal, the outline or the background). And how many pairs."""
    ink = np.round(DIAGONAL_INK * 255).astype(int)
    flag = np.array([int(FLAG_COLOUR[i:i + 2], 16) for i in (1, 3, 5)])
    on_diagonal = (panel == ink).all(axis=-1)
    rows, columns = np.nonzero(on_diagonal)
    points = np.stack([columns, rows], axis=1).astype(float)
    _, _, axes = np.linalg.svd(points - points.mean(axis=0))
    normal = axes[1]
    surface = ~on_diagonal & ~(panel == flag).all(axis=-1) & ~(panel == 255).all(axis=-1)
    steps = []
    height, width = on_diagonal.shape
    for x, y in points:
        a = np.round([x, y] + OFFSET * normal).astype(int)
        b = np.round([x, y] - OFFSET * normal).astype(int)
        if (0 <= a).all() and (0 <= b).all() and a[0] < width and b[0] < width and a[1] < height and b[1] < height:
            if surface[a[1], a[0]] and surface[b[1], b[0]]:
                steps.append(np.abs(panel[a[1], a[0]] - panel[b[1], b[0]]).max())
    return (float(np.median(steps)) if steps else 0.0), len(steps)


def test_a_folded_quad_s_split_steps_in_brightness_across_its_diagonal_and_exact_does_not(tmp_path):
    """The rule's own example (the unit square with corner 2 lifted by 1: the triangles meet at 60 degrees)
    among flat neighbours: the split panel's two triangles differ by a visible step at the drawn diagonal, the
    exact panel's curved patch changes by less than a third as much over the same six pixels."""
    from affinity.report.build import ReportOptions, collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    positions = [[0, 0, 0], [1, 0, 0], [1, 1, 1], [0, 1, 0], [2, 0, 0], [2, 1, 0], [-1, 0, 0], [-1, 1, 0]]
    fold = mesh_from_polygons("fold", positions, [[0, 1, 2, 3], [1, 4, 5, 2], [6, 0, 3, 7]])
    write_obj(fold, tmp_path / "fold.obj")
    result = collect_mesh(MeshInput(str(tmp_path / "fold.obj"), "fold.obj"), Settings(select=["Q202"]),
                          options=ReportOptions(max_views=1))
    (view,) = result.closeups
    assert view.place.code == "Q202" and view.place.worst == 0 and "diagonal" in view.texture
    split = np.round(view.images["split"] * 255).astype(int)
    exact = np.round(view.images["exact"] * 255).astype(int)
    split_step, pairs = step_across_diagonal(split)
    assert pairs >= 20 and split_step >= VISIBLE_STEP
    exact_step, _ = step_across_diagonal(exact)
    assert exact_step < split_step / 3


@pytest.mark.parametrize("name", ["spot_control_mesh.obj", "makehuman_base_hm08.obj"])  # their 8 close-ups hold Q202s
def test_every_fold_closeup_of_a_shared_mesh_shows_the_step(name, tmp_path):
    if not SHARED_MESHES.is_dir():
        pytest.skip("../shared/meshes is absent")
    report = tmp_path / "report.html"
    built = run("report", "-q", str(SHARED_MESHES / name), "--max-views", "8", "-o", str(report))
    assert built.returncode == 0, built.stderr
    parser = Closeups()
    parser.feed(report.read_text(encoding="utf-8"))
    folds = [figure for figure in parser.figures if figure["rule"] in FOLD_RULES]
    assert folds  # each of these meshes has Q202 findings with a close-up
    for figure in folds:
        step, pairs = step_across_diagonal(decode_panel(figure["images"]["split"]))
        assert pairs >= 3 and step >= VISIBLE_STEP, (name, figure["face"], step, pairs)
