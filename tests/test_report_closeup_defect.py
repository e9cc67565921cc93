"""Close-ups framed on the crease (issue 57): on shared meshes with Q101/Q102 findings, each close-up's panels,
encoded as the report writes them and decoded, show the crease on the flagged quad.

The quad's footprint is its four corners projected by the close-up's camera (render.camera's look-at and
perspective, not the rasterizer) and filled as a polygon. On it: the split and exact panels differ by at least
8/255 on a 5 x 5 block (a texture), or their lines move by at least 4 pixels (the line pattern); the difference
panel has a connected region of at least 40 pixels at 32/255 or more touching it; and the error map's largest value
there is within 10 % of the finding's shift (the shift kept beside C where the finding reads a texture).

Where the quad bends off its plane or has a reflex or repeated corner, the finding's closed form is a bound (or the
error map holds parallax), and the close-up's caption must say so instead.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.closeup_panels import decode_panel
from helpers.corpus import SHARED_MESHES

MESHES = {
    "textured spot": SHARED_MESHES / "textured" / "spot_control_mesh_textured.obj",
    "car": SHARED_MESHES / "osd_catmark_car.obj",
    "makehuman": SHARED_MESHES / "makehuman_base_hm08.obj",
    "uv sphere": SHARED_MESHES / "gen_uv_sphere_64x32.obj",
}
#: Every other shared mesh with a Q101 or Q102 finding (``affinity check ../shared/meshes``).
OTHERS = {name: SHARED_MESHES / name for name in (
    "spot_control_mesh.obj", "gen_spot_cc4.obj", "gen_vase_revolution.obj", "osd_catmark_bishop.obj",
    "osd_catmark_torus.obj", "tinyobjloader_cube_vertexcol.obj")}
#: Close-ups tested per mesh (the worst places, as the report picks them); more under ``-m slow``.
FAST, SLOW = 2, 6
STEP, BLOCK, MOVE = 8, 5, 4
REGION, BRIGHT = 40, 32
AGREES = 0.1


def _closeups(path, count: int) -> list:
    """The first ``count`` close-ups of the Q101/Q102 places of the mesh at ``path``, as the report draws them."""
    from affinity.draw import closeup
    from affinity.pipeline.check import load_and_check
    from affinity.report.places import choose_places, places_of
    from affinity.settings import Settings

    if not path.exists():
        pytest.skip(f"{path} is absent")
    settings = Settings()
    file, mesh = load_and_check(str(path), settings, scores=True)
    by_rule = {hits.code: places_of(mesh, hits) for hits in file.hits if hits.code in ("Q101", "Q102")}
    places = choose_places(by_rule, 10**6)
    assert places, f"{path.name} has no Q101/Q102 place"
    drawn = []
    for place in places:
        if any(place.worst in view.place.faces for view in drawn):
            continue
        view = closeup(mesh, place, settings)
        if view.dropped is None:
            drawn.append(view)
        if len(drawn) == count:
            break
    return [(mesh, view) for view in drawn]


def _png(image: np.ndarray) -> np.ndarray:
    """``image`` (S, S, 3) float as the report writes it (a PNG data URI), decoded to int RGB."""
    from affinity.report.images import image_uri

    return decode_panel(image_uri(image))


def _footprint(mesh, view, size: int) -> np.ndarray:
    """(S, S) bool: the worst quad's corners projected by the close-up's camera, filled as a polygon."""
    from PIL import Image, ImageDraw

    from affinity.draw.framing import UP_AXES
    from render.camera import Camera, to_clip

    face = view.place.worst
    corners = mesh.positions[mesh.corner_vertex[mesh.face_start[face]:mesh.face_start[face + 1]]]
    eye, target, fov = view.view.camera
    camera = Camera(tuple(eye), tuple(target), UP_AXES[view.view.up], fov_y=fov, near=1e-6, far=1e6)
    clip = to_clip(corners, camera.matrix)
    x = (clip[:, 0] / clip[:, 3] + 1) * size / 2
    y = (1 - clip[:, 1] / clip[:, 3]) * size / 2
    picture = Image.new("1", (size, size))
    ImageDraw.Draw(picture).polygon(list(zip(x.tolist(), y.tolist())), fill=1)
    return np.asarray(picture, dtype=bool)


def _has_block(mask: np.ndarray, side: int) -> bool:
    """Whether ``mask`` (H, W) bool holds a ``side`` x ``side`` block of True (erosion by a square)."""
    from scipy.ndimage import binary_erosion

    return bool(binary_erosion(mask, np.ones((side, side), dtype=bool)).any())


def _lines_move(split: np.ndarray, exact: np.ndarray, where: np.ndarray) -> float:
    """The farthest a line pixel of one panel on ``where`` lies from every line pixel of the other (pixels): ink
    is a pixel at least 60/255 from the pattern's paper colour."""
    from scipy.ndimage import distance_transform_edt

    from affinity.draw.texture import PAPER

    paper = np.round(PAPER * 255)
    ink = [np.abs(panel - paper).max(axis=-1) >= 60 for panel in (split, exact)]
    moved = [distance_transform_edt(~other)[mine & where].max(initial=0.0)
             for mine, other in (ink, ink[::-1]) if other.any()]
    return float(max(moved, default=0.0))


def _check(mesh, view) -> None:
    from scipy.ndimage import binary_erosion, label

    size = view.images["split"].shape[0]
    quad = _footprint(mesh, view, size)
    inner = binary_erosion(quad, iterations=2)
    assert inner.sum() >= 25, (view.place.worst, int(quad.sum()))
    split, exact = _png(view.images["split"]), _png(view.images["exact"])
    name = f"{view.place.code} face {view.place.worst}"
    if view.texture.startswith("lines"):
        assert _lines_move(split, exact, inner) >= MOVE, name
    else:
        assert _has_block((np.abs(split - exact).max(axis=-1) >= STEP) & inner, BLOCK), name
    bright = _png(view.difference).max(axis=-1) >= BRIGHT
    labels, _ = label(bright)
    touching = np.unique(labels[bright & quad])
    sizes = np.bincount(labels.ravel())
    assert touching.size and sizes[touching].max() >= REGION, (name, view.difference_gain)
    finding = view.place.shift if np.isfinite(view.place.shift) else view.place.value
    largest = float(view.error[inner & view.covered].max())
    if abs(largest - finding) > AGREES * finding:  # only where the closed form is a bound, or parallax adds: said
        assert _bent_or_reflex(mesh, view.place.worst), (name, largest, finding)
        assert "reflex" in view.crease or "off its plane" in view.crease, (name, view.crease)


def _bent_or_reflex(mesh, face: int) -> bool:
    """Whether quad ``face``'s corners lie more than 5 % of its longer diagonal off their best-fit plane, or
    one of its corners is reflex or repeated (seen along its plane's normal)."""
    corners = mesh.positions[mesh.corner_vertex[mesh.face_start[face]:mesh.face_start[face + 1]]]
    centred = corners - corners.mean(axis=0)
    normal = np.linalg.svd(centred)[2][2]
    diagonal = max(np.linalg.norm(corners[2] - corners[0]), np.linalg.norm(corners[3] - corners[1]))
    edges = np.roll(corners, -1, axis=0) - corners
    turns = np.cross(edges, np.roll(edges, -1, axis=0)) @ normal
    return bool(np.ptp(centred @ normal) > 0.05 * diagonal or (np.abs(turns) < 1e-12 * diagonal**2).any()
                or len(set(np.sign(turns))) > 1)


@pytest.mark.parametrize("mesh", list(MESHES))
def test_closeups_show_the_crease_on_the_flagged_quad(mesh):
    for drawn, view in _closeups(MESHES[mesh], FAST):
        _check(drawn, view)


#: Known gaps: a folded quad (Spot's face 37 bends 112 degrees; one of Spot cc4's) whose lines do not move 4 px.
FOLDED = pytest.mark.xfail(strict=True, reason="a sharply folded quad's crease is not framed yet (issue 57)")


@pytest.mark.slow
@pytest.mark.parametrize("mesh", [*MESHES, *(pytest.param(name, marks=FOLDED) if name in (
    "spot_control_mesh.obj", "gen_spot_cc4.obj") else name for name in OTHERS)])
def test_every_closeup_of_a_report_shows_the_crease_on_the_flagged_quad(mesh):
    for drawn, view in _closeups({**MESHES, **OTHERS}[mesh], SLOW)[FAST if mesh in MESHES else 0:]:
        _check(drawn, view)


def test_the_crease_is_found_where_the_closed_form_puts_it():
    """The trapezoid of Q101's documentation (side ratio 1/2, the unit square of uv at 1024 texels): along 0-2 the
    split's largest shift is (1 - r) / (1 + sqrt r)^2 of the width, on the diagonal; dense sampling finds both."""
    from affinity.draw.defect import SAMPLES, quad_defect

    corners = np.array([[-1, 0, 0], [1, 0, 0], [0.5, 1, 0], [-0.5, 1, 0]], dtype=float)
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    defect = quad_defect(corners, uv, np.array([1024.0, 1024.0]), uv * 1024)
    r = 0.5
    assert defect.shift == pytest.approx(1024 * (1 - r) / (1 + np.sqrt(r)) ** 2, rel=1e-3)
    along = corners[2] - corners[0]  # the largest split error lies on the split's diagonal (measures.split_error_point)
    assert abs(np.cross(along, defect.point - corners[0])[2]) <= 2 / (SAMPLES - 1) ** 2 * np.linalg.norm(along)
    assert defect.texel == pytest.approx(np.sqrt(1.5 / 1024**2))  # the quad's area over its uv's, per texel
    assert not defect.folded and defect.bend == 0
