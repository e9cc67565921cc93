"""Close-ups of flagged places, the UV layout and the overview's framing, against independent truth."""

from __future__ import annotations

import re

import numpy as np
import pytest
from helpers.cli import run
from helpers.corpus import ABSENT, SHARED_MESHES, shared_mesh_paths
from helpers.quads import UNIT_UV, quad_obj, trapezoid

from affinity.loaders import load
from affinity.loaders.objwriter import write_obj
from affinity.mesh import mesh_from_polygons

needs_meshes = pytest.mark.skipif(not SHARED_MESHES.is_dir(), reason=ABSENT)


def grid_mesh(n: int = 10, bent: tuple = ()) -> object:
    """An n x n grid of unit quads in the z = 0 plane with uv = position / n, except the quads in ``bent``
    ((row, col) pairs), whose top-right corner's uv is pushed (a disaffine quad needs its own uv corners)."""
    xs, ys = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0))
    positions = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1)
    row, col = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    first = (row * (n + 1) + col).ravel()
    faces = np.stack([first, first + 1, first + n + 2, first + n + 1], axis=1)
    # One uv per corner: corners are numbered 4 * face + k.
    corner_positions = positions[faces].reshape(-1, 3)
    uv = corner_positions[:, :2] / n
    for r, c in bent:
        uv[4 * (r * n + c) + 2] += 0.3 / n
    mesh = mesh_from_polygons("grid", corner_positions, np.arange(4 * n * n).reshape(-1, 4), texcoords=uv)
    return mesh


def welded_grid(n: int = 10, bent: tuple = ()) -> object:
    """:func:`grid_mesh` with its corners welded: neighbouring quads share vertices (uv stays per corner)."""
    from affinity.mesh import Mesh

    xs, ys = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0))
    positions = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], axis=1)
    row, col = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    first = (row * (n + 1) + col).ravel()
    faces = np.stack([first, first + 1, first + n + 2, first + n + 1], axis=1)
    return Mesh(**{**grid_mesh(n, bent).__dict__, "corner_vertex": faces.ravel(), "positions": positions})


def test_connected_components_agree_with_a_breadth_first_search():
    from affinity.report.places import connected_components

    rng = np.random.default_rng(7)
    n = 300
    a, b = rng.integers(0, n, 200), rng.integers(0, n, 200)
    label = connected_components(n, a, b)
    neighbours = [[] for _ in range(n)]
    for x, y in zip(a.tolist(), b.tolist()):
        neighbours[x].append(y)
        neighbours[y].append(x)
    truth = np.full(n, -1)
    for start in range(n):  # plain BFS, components named by their smallest node
        if truth[start] >= 0:
            continue
        truth[start], queue = start, [start]
        while queue:
            for other in neighbours[queue.pop()]:
                if truth[other] < 0:
                    truth[other] = start
                    queue.append(other)
    np.testing.assert_array_equal(label, truth)


def test_faces_sharing_a_vertex_are_one_place_and_separated_patches_are_two():
    from affinity.lint import lint_mesh
    from affinity.report.places import places_of
    from affinity.settings import Settings

    # Faces (2,2) and (3,3) touch at one corner; (7,7) is apart.
    welded = welded_grid(10, bent=[(2, 2), (3, 3), (7, 7)])
    (hits,) = lint_mesh(welded, Settings(select=["Q101"]))
    assert sorted(hits.faces.tolist()) == [22, 33, 77]
    places = places_of(welded, hits)
    assert sorted(sorted(p.faces.tolist()) for p in places) == [[22, 33], [77]]


def test_a_place_has_the_level_of_its_worst_finding(tmp_path):
    """Severity by visibility reaches the report: above 2 texels a place is an error, below a warning."""
    from affinity.pipeline.check import load_and_check
    from affinity.report.places import places_of
    from affinity.settings import Settings

    path = tmp_path / "two.obj"
    path.write_text(quad_obj([(trapezoid(1.0), UNIT_UV), (trapezoid(1.992, x=5.0), UNIT_UV)]))
    file, mesh = load_and_check(str(path), Settings(select=["Q101"]))
    places = places_of(mesh, file.hits[0])
    assert len(places) == 2 and min(p.value for p in places) < 2.0 < max(p.value for p in places)
    assert all(p.level == ("error" if p.value > 2.0 else "warning") for p in places)


def test_places_go_errors_first_then_take_turns_between_rules_worst_first():
    from affinity.report.places import Place, choose_places

    def place(code, beyond, face, level="warning"):
        return Place(code, np.array([face]), np.array([beyond]), face, beyond, beyond, level)

    by_rule = {"Q101": [place("Q101", 9.0, 1, "error"), place("Q101", 5.0, 2, "error"), place("Q101", 4.0, 3)],
               "Q202": [place("Q202", 2.0, 4)], "Q204": [place("Q204", 1.5, 5, "error")],
               "Q302": [place("Q302", 1.0, 6, "info")]}
    chosen = choose_places(by_rule, 6)
    assert [(p.code, p.worst) for p in chosen] == [("Q101", 1), ("Q204", 5), ("Q101", 2), ("Q101", 3),
                                                   ("Q202", 4), ("Q302", 6)]
    assert [p.level for p in choose_places(by_rule, 3)] == ["error"] * 3
    assert choose_places(by_rule, 0) == []


def test_a_place_repeats_its_mirror_twin_and_its_group_s_parts_with_values_within_a_tenth():
    """A symmetric model's two halves: positions mirror exactly, an atlas's values only roughly (MakeHuman's
    lip: 3.467695 and 3.467417 texels; Spot's cheeks: 1.030 and 0.996). Parts carved from one group repeat it
    wherever they lie when their values agree as closely."""
    from affinity.report.places import Place, repeats

    centroids = np.array([[0.33, 7.2, 1.4], [-0.33, 7.2, 1.4], [-0.33, 7.2, 1.4], [0.5, 2.0, 0.0], [-0.5, 2.1, 0.0],
                          [4.0, -6.0, 2.0], [4.0, -6.0, 2.0]])
    low, high = np.array([-5.0, -8.0, -1.0]), np.array([5.0, 8.0, 3.0])
    values = [3.467695, 3.467417, 4.5, 2.0, 2.0, 3.3, 3.3]
    groups = [0, 1, 2, 3, 4, 0, 0]

    def place(face, code="Q101"):
        return Place(code, np.array([face]), np.array([values[face]]), face, values[face], 1.0, "warning",
                     groups[face])

    def repeat(a, b, code="Q101"):
        return repeats(place(a, code), place(b), centroids, low, high)

    # 1 mirrors 0 with a value 8e-5 apart; 2 mirrors it at a value 30 % off; 4 is no mirror image of 3 (y differs).
    assert repeat(1, 0) and not repeat(2, 0) and not repeat(4, 3)
    assert not repeat(1, 0, code="Q202")  # another rule's finding is news
    assert repeat(5, 0) and not repeat(6, 1)  # 5 is a part of 0's group 5 % off; 6 is no part of 1's
    alone = Place("Q101", np.array([6]), np.array([3.3]), 6, 3.3, 1.0, "warning")  # a place of its own
    assert not repeats(alone, place(5), centroids, low, high)


def test_a_place_an_earlier_closeup_shows_gets_no_closeup_of_its_own(tmp_path):
    """Two neighbouring flagged quads cut into two places (--place-faces 1): the first close-up shows both, so
    there is one close-up (the other place is counted as not drawn); far apart, each gets its own."""
    from affinity.report.build import ReportOptions, collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    counts = []
    for bent in ([(5, 5), (4, 5)], [(1, 1), (10, 10)]):  # not mirror images of each other
        write_obj(grid_mesh(12, bent=bent), tmp_path / "two.obj")
        result = collect_mesh(MeshInput(str(tmp_path / "two.obj"), "two.obj"), Settings(),
                              options=ReportOptions(place_faces=1))
        assert len(result.places) == 2
        counts.append(len(result.closeups))
        first = result.closeups[0]
        other = next(p for p in result.places if p is not first.place)
        assert (other.worst in first.seen) == (len(result.closeups) == 1)
    # Far apart, each gets its own. Side by side, the first close-up is zoomed on its crease (issue 57): whether
    # the neighbour still covers SEEN_PIXELS there decides, as asserted per case above.
    assert counts[1] == 2


def test_closeup_camera_looks_at_the_place_along_its_normal_and_fits_its_ring():
    from affinity.draw.closeup import TILT_DEGREES, closeup_view
    from affinity.draw.faces import face_subset
    from affinity.draw.framing import camera_for
    from render import to_clip

    mesh = welded_grid(10)
    view = closeup_view(mesh, np.array([55]))
    eye, target, _ = view.camera
    np.testing.assert_allclose(target, [5.5, 5.5, 0.0])
    direction = np.subtract(eye, target) / np.linalg.norm(np.subtract(eye, target))
    assert np.degrees(np.arccos(direction[2])) == pytest.approx(TILT_DEGREES)  # the normal is +z
    # Every corner of the place's ring projects inside the picture, and the place near its centre.
    camera = camera_for(mesh, 240, 240, view.camera, view.up)
    clip = to_clip(mesh.positions, camera.matrix)
    ndc = clip[:, :2] / clip[:, 3:]
    ring_corners = face_subset(mesh, view.ring).corner_vertex
    assert np.abs(ndc[ring_corners]).max() < 1.0
    assert np.abs(ndc[face_subset(mesh, np.array([55])).corner_vertex].mean(axis=0)).max() < 0.05
    assert view.ring.tolist() == [44, 45, 46, 54, 55, 56, 64, 65, 66]  # the quad and its eight neighbours


def _worst_face_share(tmp_path, bent) -> tuple:
    """Report a welded 30 x 30 grid whose ``bent`` quads are flagged; the first close-up, its place and the share
    of its picture the place's worst face covers (a depth-tested face-id render at its camera)."""
    from affinity.draw.closeup import place_pixels
    from affinity.report.build import collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    write_obj(welded_grid(30, bent=bent), tmp_path / "grid.obj")
    mesh = load(str(tmp_path / "grid.obj"))
    first = collect_mesh(MeshInput(str(tmp_path / "grid.obj"), "grid.obj"), Settings()).closeups[0]
    return first, float(place_pixels(mesh, first.view, np.array([first.place.worst]), 240, 240).mean())


def test_a_long_place_is_framed_on_its_worst_face_and_a_compact_one_whole(tmp_path):
    """A row of 24 flagged unit quads framed whole would leave each about 10 pixels wide: the close-up frames the
    worst one and its neighbours instead. Seen from 20 degrees off the normal, a unit quad filling the picture
    as the ring frame puts it (half-height = radius / FILL) covers (240 / (2 tan(15) d))^2 cos(20) pixels."""
    from affinity.draw.closeup import CLOSEUP_FOV, FILL, RING_RADII, TILT_DEGREES

    first, share = _worst_face_share(tmp_path, [(15, c) for c in range(3, 27)])
    assert len(first.place.faces) == 24
    worst = divmod(first.place.worst, 30)
    target = np.asarray(first.view.camera[1])  # on the worst quad (its crease, issue 57)
    assert worst[1] <= target[0] <= worst[1] + 1 and worst[0] <= target[1] <= worst[0] + 1 and target[2] == 0
    radius = RING_RADII * np.sqrt(0.5)  # the ring reaches farther (1.5 sqrt 2) than twice the quad's own radius
    half = np.radians(CLOSEUP_FOV / 2)
    distance = radius / (FILL * np.sin(half))
    expected = (1 / (2 * np.tan(half) * distance)) ** 2 * np.cos(np.radians(TILT_DEGREES))
    assert share >= expected * 0.85  # zoomed on the worst quad's crease (issue 57), it covers at least that
    assert first.framed == f"face {first.place.worst} and its neighbours"

    # A pair framed whole is sqrt(5) / sqrt(2) as wide as its worst quad's frame (twice its own radius, sqrt(5) / 2,
    # against twice the quad's): framed whole, around the pair's centre.
    pair, _ = _worst_face_share(tmp_path, [(15, 14), (15, 15)])
    target = np.asarray(pair.view.camera[1])  # then zoomed on the worst quad's crease (issue 57)
    assert 14 <= target[0] <= 16 and 15 <= target[1] <= 16 and target[2] == 0
    assert pair.framed == "the place's faces and their neighbours"


def test_a_compact_place_whose_worst_face_is_hidden_from_every_side_is_framed_on_that_face(tmp_path):
    """A flagged pair (worst quad 465 at x, y in [15, 16]) under two flaps, 2.6 wide at z = +-2 over the worst
    quad: framed whole (radius sqrt(5)), the flaps are drawn and hide it from all six candidate directions
    (a 20-degree tilt moves a flap's shadow by 2 tan 20 = 0.73 < its 0.8 margin), while the other quad still
    shows. Framed on the worst quad (radius sqrt(2) < 2 cos 20), the flaps are not drawn and it shows."""
    from affinity.draw.closeup import place_pixels
    from affinity.report.build import collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    path = tmp_path / "flaps.obj"
    write_obj(welded_grid(30, bent=[(15, 14), (15, 15), (15, 15)]), path)  # 961 v, 3600 vt
    corners = [(14.2, 14.2), (16.8, 14.2), (16.8, 16.8), (14.2, 16.8)]
    flaps = [f"v {x} {y} {z}" for z in (2.0, -2.0) for x, y in corners]
    flaps += ["vt 0 0", "vt 1 0", "vt 1 1", "vt 0 1", "f 962/3601 963/3602 964/3603 965/3604",
              "f 969/3604 968/3603 967/3602 966/3601"]
    with open(path, "a", encoding="utf-8") as file:
        file.write("\n".join(flaps) + "\n")
    first = collect_mesh(MeshInput(str(path), "flaps.obj"), Settings()).closeups[0]
    assert first.place.faces.tolist() == [464, 465] and first.place.worst == 465
    assert first.framed == "face 465 and its neighbours"
    worst_pixels = place_pixels(load(str(path)), first.view, np.array([465]), 240, 240).sum()
    assert worst_pixels >= 300


def test_a_closeup_s_error_map_spans_its_ramp_over_the_place(tmp_path):
    """A bent quad's split error peaks along its diagonal and falls to 0 at its edges: with the ramp ending at the
    place's largest error only that pixel would be dark red. It ends where the place's worst 5 % begin, so about
    that share of the place's pixels saturate and the rest spread over the ramp."""
    import base64
    import io

    from PIL import Image

    from affinity.report.build import collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.report.images import HEAT_STOPS
    from affinity.report.sections import closeups_section
    from affinity.settings import Settings

    write_obj(welded_grid(12, bent=[(6, 6)]), tmp_path / "bent.obj")
    result = collect_mesh(MeshInput(str(tmp_path / "bent.obj"), "bent.obj"), Settings())
    figure = closeups_section(result).data["figures"][0]
    heat = np.asarray(Image.open(io.BytesIO(base64.b64decode(figure["error"]["src"].split(",", 1)[1]))).convert("RGB"))
    place = result.closeups[0].own & result.closeups[0].covered
    darkest = np.round(np.array(HEAT_STOPS[-1]) * 255)
    saturated = (np.abs(heat[place] - darkest).max(axis=1) <= 1).mean()
    assert 0.03 <= saturated <= 0.08
    assert (np.abs(heat[place] - 255).max(axis=1) > 60).mean() > 0.5  # most of the place is visibly tinted


def test_line_pattern_inks_each_pixel_by_its_coverage_of_a_line():
    """A u ramp of one footprint per pixel: the ink of a 1.5 px box-filtered line, from its closed form."""
    from affinity.draw.texture import LINE_SPACING, LINE_WIDTH, PAPER, U_INK, line_colours, pixel_footprint

    footprint = 1e-4
    columns = np.arange(64) + 0.5  # pixel centres
    uv = np.stack([columns * footprint, np.full(64, 0.5 * LINE_SPACING * footprint)], axis=1)  # v between lines
    assert pixel_footprint(uv.reshape(1, 64, 2)) == pytest.approx(footprint)
    ink = (line_colours(uv, footprint) - PAPER)[:, 0] / (U_INK - PAPER)[0]
    distance = np.abs(columns - LINE_SPACING * np.round(columns / LINE_SPACING))  # pixels to the nearest u line
    coverage = np.clip(np.minimum(distance + LINE_WIDTH / 2, 0.5) - np.maximum(distance - LINE_WIDTH / 2, -0.5), 0, 1)
    assert np.allclose(ink, coverage, atol=1e-6)


def test_glyph_is_a_box_filtered_upright_f_whose_mirror_images_differ():
    """One glyph cell, pixel by pixel: the ink against 16 x 16 supersampling of the F's strokes, and the F
    mirrored in u or in v is not the F (so a mirrored island shows), and it fades out in small cells."""
    from affinity.draw.texture import GLYPH_SPACING, GLYPH_STROKES, glyph_ink

    footprint = 1e-3
    side = int(GLYPH_SPACING)
    centres = np.arange(side) + 0.5
    u, v = np.meshgrid(centres, centres, indexing="ij")
    uv = np.stack([u.ravel(), v.ravel()], axis=1) * footprint
    local = np.full_like(uv, footprint)
    ink = glyph_ink(uv, footprint, local).reshape(side, side)

    offsets = (np.arange(16) + 0.5) / 16 - 0.5
    su, sv = (np.add.outer(centres, offsets) / side).reshape(-1), (np.add.outer(centres, offsets) / side).reshape(-1)
    inside_u = (GLYPH_STROKES[:, 0] <= su[:, None]) & (su[:, None] <= GLYPH_STROKES[:, 1])  # (side * 16, 3)
    inside_v = (GLYPH_STROKES[:, 2] <= sv[:, None]) & (sv[:, None] <= GLYPH_STROKES[:, 3])
    union = (inside_u[:, None, :] & inside_v[None, :, :]).any(axis=2)  # (side * 16, side * 16)
    sampled = union.reshape(side, 16, side, 16).mean(axis=(1, 3))
    assert np.abs(ink - sampled).max() < 0.3 and np.abs(ink - sampled).mean() < 0.01
    assert sampled.sum() > 0.1 * side * side  # the strokes are there to be seen

    mirrored_u = glyph_ink(uv * [-1, 1], footprint, local).reshape(side, side)
    mirrored_v = glyph_ink(uv * [1, -1], footprint, local).reshape(side, side)
    for mirrored in (mirrored_u, mirrored_v):
        assert (np.abs(mirrored - ink) > 0.5).mean() > 0.05
    assert glyph_ink(uv, footprint, local * side / 8).max() == 0.0  # cells of 8 pixels: no glyph


def test_a_mirrored_uv_closeup_draws_glyphs_and_a_disaffine_one_does_not(tmp_path):
    """Q302 (mirroring is the finding) gets the F glyph over the lines; Q101 lines only."""
    from affinity.draw.texture import GLYPH_INK
    from affinity.report.build import ReportOptions, collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    mesh = grid_mesh(8, bent=[(1, 1)])
    uv = mesh.texcoords.copy()
    corner_x = mesh.positions[mesh.corner_vertex][:, 0]
    right = corner_x.reshape(-1, 4).min(axis=1) >= 5  # columns 5-7 mirrored in u: flipped, still affine
    mirrored = np.repeat(right, 4)
    uv[mirrored, 0] = (13 - corner_x[mirrored]) / 8
    write_obj(replace_uv(mesh, uv), tmp_path / "mirrored.obj")
    result = collect_mesh(MeshInput(str(tmp_path / "mirrored.obj"), "mirrored.obj"), Settings(),
                          options=ReportOptions(max_views=6))
    by_code = {view.place.code: view for view in result.closeups}
    assert {"Q101", "Q302"} <= by_code.keys()
    dark = {code: (np.abs(view.images["exact"] - GLYPH_INK).max(axis=-1) < 0.08).mean()
            for code, view in by_code.items()}
    assert "upright F" in by_code["Q302"].texture and "F" not in by_code["Q101"].texture
    assert dark["Q302"] > 0.02 and dark["Q101"] == 0.0


@pytest.mark.parametrize(("difference", "gain"), [(5 / 255, 20), (3 / 255, 20), (0.004, 100), (0.3, 1), (1e-3, 500),
                                                  (0.0, 1), (0.9, 1)])
def test_gain_brings_the_largest_change_to_about_half(difference, gain):
    from affinity.draw.closeup import gain_for

    assert gain_for(difference) == gain  # 1, 2 or 5 times a power of ten, the most that keeps it at <= 0.5


def test_amplified_difference_is_exact_plus_gain_times_the_split_s_change():
    from affinity.draw.closeup import amplified_difference

    rng = np.random.default_rng(3)
    exact = rng.uniform(0.35, 0.65, (16, 16, 3))  # never clipped at the gain
    split = exact + rng.uniform(-4, 4, (16, 16, 3)) / 255
    same = rng.random((16, 16)) < 0.8
    split[~same] = 0.0  # another face there: a silhouette, not a crease
    image, gain = amplified_difference(split, exact, same)
    assert gain == 20  # largest change under 4/255: 0.5 / (4 / 255) = 31.9
    np.testing.assert_allclose(image[same], (exact + gain * (split - exact))[same], atol=1e-6)
    np.testing.assert_allclose(image[~same], exact[~same], atol=1e-6)


def test_a_faint_colour_crease_gets_an_amplified_panel_that_shows_it(tmp_path):
    """One unit square, grey but for one corner 12/255 lighter (colours bilinear, not affine): the split's
    crease is a few 1/255 at true size, and tens of 1/255 in the amplified panel."""
    from affinity.draw.shading import OVERLAY_TINT
    from affinity.report.build import ReportOptions, collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    colors = np.full((4, 3), 0.5)
    colors[2] += 12 / 255
    square = mesh_from_polygons("faint", [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]], colors=colors)
    write_obj(square, tmp_path / "faint.obj")
    result = collect_mesh(MeshInput(str(tmp_path / "faint.obj"), "faint.obj"), Settings(),
                          options=ReportOptions(max_views=1))
    (view,) = result.closeups
    assert view.place.code == "Q102" and view.gain >= 10
    split, exact = view.images["split"], view.images["exact"]
    inside = view.covered & ~(split == OVERLAY_TINT).all(axis=-1)
    true_size = np.abs(split - exact).max(axis=-1)[inside]
    shown = np.abs(view.amplified - exact).max(axis=-1)[inside]
    assert true_size.max() < 6 / 255 and (shown > 20 / 255).mean() > 0.05


def test_amplified_uv_moves_the_split_s_texture_by_gain_times_its_error():
    from affinity.draw.closeup import UV_REACH, amplified_uv

    rng = np.random.default_rng(5)
    exact = rng.uniform(0, 1, (12, 12, 2))
    local = np.full((12, 12, 2), 1e-3)
    split = exact + rng.uniform(-0.4e-3, 0.4e-3, (12, 12, 2))  # under 0.4 pixels
    same = np.ones((12, 12), dtype=bool)
    same[0] = False
    uv, gain = amplified_uv(split, exact, same, local)
    largest = np.abs(split - exact)[same].max() / 1e-3
    assert gain * largest <= UV_REACH < 2.5 * gain * largest  # the next step (x2 or x2.5) would pass the reach
    np.testing.assert_allclose(uv[same], (exact + gain * (split - exact))[same])
    np.testing.assert_array_equal(uv[~same], exact[~same])


def test_a_sub_texel_uv_crease_is_zoomed_until_its_lines_move_by_pixels(tmp_path):
    """One quad's corner uv pushed by 2 texels (a 0.71-texel crease): the close-up zooms on it (issue 57) to
    8 px per texel, capped where the quad's diagonal spans two panels (145 texels: 3.3 px per texel), so the
    split moves its lines by over 2 pixels and no amplified panel is needed."""
    from affinity.report.build import ReportOptions, collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    mesh = grid_mesh(10)
    uv = mesh.texcoords.copy()
    uv[4 * 44 + 2] += 2 / 1024
    write_obj(replace_uv(mesh, uv), tmp_path / "faint_uv.obj")
    result = collect_mesh(MeshInput(str(tmp_path / "faint_uv.obj"), "faint_uv.obj"), Settings(),
                          options=ReportOptions(max_views=1))
    (view,) = result.closeups
    assert view.place.code == "Q101" and view.gain == 1 and view.amplified is None
    diagonal = np.hypot(1024 / 10, 1024 / 10)  # texels: the grid's quads are a tenth of the texture wide
    assert view.zoom == pytest.approx(2 * 240 / diagonal, rel=0.1)
    assert view.error[view.covered].max() * view.zoom > 2  # pixels


def replace_uv(mesh, uv):
    """``mesh`` with per-corner texture coordinates ``uv`` (C, 2)."""
    return mesh_from_polygons("grid", mesh.positions[mesh.corner_vertex],
                              np.arange(len(uv)).reshape(-1, 4), texcoords=uv)


def test_outline_is_the_border_of_the_mask():
    from affinity.draw.closeup import outline

    mask = np.zeros((10, 10), dtype=bool)
    mask[2:8, 3:9] = True
    ring = outline(mask, width=1)
    assert ring.sum() == 2 * 6 + 2 * 4 and not ring[3:7, 4:8].any() and (ring <= mask).all()


def test_a_sliver_place_gets_a_halo_outside_it():
    from affinity.draw.closeup import SLIVER_PIXELS, outline

    mask = np.zeros((9, 9), dtype=bool)
    mask[4, 2:7] = True  # 5 pixels: a folded quad seen nearly edge-on
    ring = outline(mask, width=2)
    assert mask.sum() < SLIVER_PIXELS and (ring >= mask).all()
    distance = np.abs(np.arange(9)[:, None] - 4) + np.maximum(np.maximum(2 - np.arange(9), np.arange(9) - 6), 0)[None]
    np.testing.assert_array_equal(ring, distance <= 2)  # every pixel within 2 steps of the sliver


def test_two_separated_flagged_patches_give_two_closeups_each_outlined(tmp_path):
    from html.parser import HTMLParser

    write_obj(grid_mesh(12, bent=[(2, 2), (9, 9)]), tmp_path / "two.obj")
    result = run("report", "-q", "two.obj", "-o", "out.html", cwd=tmp_path)
    assert result.returncode == 0, result.stderr

    class Figures(HTMLParser):
        def __init__(self):
            super().__init__()
            self.figures, self.current, self.views = [], None, []

        def handle_starttag(self, tag, attrs):
            attrs = dict(attrs)
            if tag == "figure" and "data-face" in attrs:
                self.current = {"face": int(attrs["data-face"]), "rule": attrs["data-rule"], "images": []}
                self.figures.append(self.current)
            if tag == "figure" and "data-view" in attrs:
                self.views.append(attrs["data-view"])
            if tag == "img" and self.current is not None:
                self.current["images"].append(attrs["src"])

        def handle_endtag(self, tag):
            if tag == "figure":
                self.current = None

    parser = Figures()
    parser.feed((tmp_path / "out.html").read_text(encoding="utf-8"))
    assert sorted((f["face"], f["rule"]) for f in parser.figures) == [(2 * 12 + 2, "Q101"), (9 * 12 + 9, "Q101")]
    assert parser.views == ["3d", "uv-layout"]  # the 3-D view, then the texture-space view
    for figure in parser.figures:
        assert has_outline_colour(figure["images"][0])


def has_outline_colour(data_uri: str) -> bool:
    """Whether a PNG data URI has pixels of exactly the flag colour."""
    import base64
    import io

    from PIL import Image

    from affinity.draw.shading import FLAG_COLOUR

    flag = [int(FLAG_COLOUR[i:i + 2], 16) for i in (1, 3, 5)]
    pixels = np.asarray(Image.open(io.BytesIO(base64.b64decode(data_uri.split(",", 1)[1]))).convert("RGB"))
    return bool((pixels.reshape(-1, 3) == flag).all(axis=1).sum() >= 20)


def test_uv_layout_fills_the_flagged_faces_in_the_flag_colour():
    from affinity.draw.shading import OVERLAY_TINT
    from affinity.report.uvlayout import layout_image

    mesh = grid_mesh(4)
    flagged = np.zeros(mesh.n_faces, dtype=bool)
    flagged[5] = True  # row 1, col 1: uv [0.25, 0.5]^2
    layout = layout_image(mesh, flagged, 64)
    image, low, side = layout.image, layout.low, layout.side
    assert side == 1.0 and tuple(low) == (0.0, 0.0)
    tinted = np.all(np.isclose(image, OVERLAY_TINT, atol=1e-6), axis=2)
    rows, cols = np.nonzero(tinted)
    # uv (0.25..0.5, 0.25..0.5) is columns 16..32 and rows 32..48 (v up, row 0 at the top), less the edge pixels.
    assert 16 <= cols.min() and cols.max() < 32 and 32 <= rows.min() and rows.max() < 48
    assert tinted.sum() > 0.7 * 16 * 16


def test_surfaces_of_revolution_stand_on_their_axis_and_everything_else_is_y_up():
    from affinity.draw.framing import guess_up_axis
    from affinity.scenes import latlong_sphere

    vase = latlong_sphere(16, 8)  # z axis of revolution, but a sphere: all extents equal -> the y convention
    assert guess_up_axis(vase) == "y"
    stretched = mesh_from_polygons("pillar", vase.positions * [1.0, 1.0, 3.0], vase.corner_vertex.reshape(-1, 4))
    assert guess_up_axis(stretched) == "z"
    lying = mesh_from_polygons("lying", stretched.positions[:, [2, 0, 1]], stretched.corner_vertex.reshape(-1, 4))
    assert guess_up_axis(lying) == "x"
    tile = grid_mesh(3)  # a square tile in the z = 0 plane lies flat: z up, seen from above
    assert guess_up_axis(tile) == "z"
    wall = mesh_from_polygons("wall", tile.positions * [1.0, 2.0, 1.0], tile.corner_vertex.reshape(-1, 4))
    # Issue 25: a sheet thinnest along z whose faces all face z reads as ground (a heightfield), z up; a
    # standing sheet, facing y, stays with the OBJ convention.
    assert guess_up_axis(wall) == "z"
    standing = mesh_from_polygons("standing", wall.positions[:, [0, 2, 1]], tile.corner_vertex.reshape(-1, 4))
    assert guess_up_axis(standing) == "y"


@needs_meshes
def test_the_car_with_up_z_is_seen_from_the_side():
    pytest.importorskip("pyvista")
    from affinity.report.build import ReportOptions, collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    car = MeshInput(str(SHARED_MESHES / "osd_catmark_car.obj"), "car")
    aspects = {}
    for up in ("z", "y"):
        result = collect_mesh(car, Settings(), options=ReportOptions(up=up, max_views=0))
        mask = np.abs(result.overview.astype(int) - 255).max(axis=2) > 10
        rows, cols = np.nonzero(mask)
        aspects[up] = np.ptp(cols) / np.ptp(rows)
    # The car is 1.0 long (y), 0.43 wide (x) and 0.2 high (z): from the side its silhouette is about five times
    # as wide as high, less the elevation and the turn; seen with the wrong up axis it stands on its nose.
    assert aspects["z"] > 2.5 and aspects["y"] < 1.0


@needs_meshes
@pytest.mark.slow  # a report of every shared mesh
def test_every_shared_mesh_with_flags_gets_closeups():
    from affinity.pipeline.check import load_and_check
    from affinity.report.build import ReportOptions, collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.settings import Settings

    for path in shared_mesh_paths("*.obj"):
        file, _ = load_and_check(str(path), Settings())
        result = collect_mesh(MeshInput(str(path), path.name), Settings(), options=ReportOptions(max_views=2))
        flagged_rules = {hits.code for hits in file.hits if (hits.faces >= 0).any()}
        assert bool(result.closeups) == bool(flagged_rules), path.name
        for closeup in result.closeups:
            hits = next(h for h in file.hits if h.code == closeup.place.code)
            assert closeup.place.worst in hits.faces
            assert (np.all(np.isclose(closeup.images["split"], [1.0, 0.1, 0.6], atol=1e-6), axis=2)).sum() >= 10


def test_a_pixel_is_stiff_where_the_catalogue_says_the_coordinates_are_ill_conditioned():
    from affinity.report.stiffness import STIFF_CONDITION, _check
    from affinity.stability.cases import catalogue

    cases = {case.name: case for case in catalogue()}
    inside, far = cases["inside"], cases["far-1e4"]  # far outside a quad: weights grow, the condition with them
    calm = _check(np.asarray(inside.points[0]), np.asarray(inside.quad), np.ones(4), 0, (0, 0))
    stiff = _check(np.asarray(far.points[0]), np.asarray(far.quad), np.ones(4), 0, (0, 0))
    assert calm.condition < 10 and not calm.stiff
    assert calm.error64 <= calm.tolerance64 and calm.error32 <= calm.tolerance32
    assert stiff.condition > STIFF_CONDITION and stiff.stiff


@pytest.mark.slow  # several reports
def test_report_options_max_views_and_a_bad_texture(tmp_path):
    write_obj(grid_mesh(6, bent=[(1, 1), (4, 4)]), tmp_path / "two.obj")

    def report(*args):
        return run("report", "-q", "two.obj", "-o", "out.html", *args, cwd=tmp_path)

    done = report("--max-views", "1", "--size", "200x150", "--up", "z")
    assert done.returncode == 0, done.stderr
    html = (tmp_path / "out.html").read_text(encoding="utf-8")
    assert html.count("<figure class=\"closeup\"") == 1 and "1 more flagged places not drawn" in html
    done = report("--max-views", "0")
    assert done.returncode == 0 and "data-face" not in (tmp_path / "out.html").read_text(encoding="utf-8")
    (tmp_path / "out.html").unlink()
    (tmp_path / "not-an-image.png").write_text("hello")
    failed = report("--texture", "not-an-image.png")
    assert failed.returncode == 2 and "not-an-image.png: not a readable image" in failed.stderr
    assert "Traceback" not in failed.stderr and not (tmp_path / "out.html").exists()


def test_uv_layout_labels_places_at_one_uv_spot_once(tmp_path):
    """Per-face unit uv (every face on the whole texture): one ring, one label naming every labelled face."""
    from affinity.report.uvlayout import layout_image, layout_svg

    path = tmp_path / "tiles.obj"
    path.write_text(quad_obj([(trapezoid(0.2 + 0.1 * k, 3 * k), UNIT_UV) for k in range(4)]))
    mesh = load(str(path))
    svg = layout_svg(mesh, layout_image(mesh, np.ones(4, bool), 640), [(3, "Q101"), (0, "Q101"), (2, "Q202")])
    assert svg.count("<circle") == 1
    assert re.findall(r"<text[^>]*>([^<]*)</text>", svg) == ["faces 3, 0 (Q101)", "face 2 (Q202)"]


def test_uv_layout_labels_crowded_at_the_bottom_stay_inside_the_picture(tmp_path):
    from affinity.report.uvlayout import layout_image, layout_svg

    # five small uv squares in a row at the bottom edge, 19 px apart: rings apart, labels colliding
    tiles = [[(0.05 + 0.03 * k + 0.004 * du, 0.003 + 0.004 * dv) for du, dv in UNIT_UV] for k in range(5)]
    path = tmp_path / "crowded.obj"
    path.write_text(quad_obj([(trapezoid(0.5, 3 * k), uv) for k, uv in enumerate(tiles)]))
    mesh = load(str(path))
    svg = layout_svg(mesh, layout_image(mesh, np.ones(5, bool), 640), [(k, "Q101") for k in range(5)])
    baselines = sorted(float(y) for y in re.findall(r'<text x="[^"]+" y="([^"]+)"', svg))
    assert len(baselines) == 5 and svg.count("<circle") == 5
    assert 12 <= baselines[0] and baselines[-1] <= 640 - 3  # none below the picture's edge
    assert min(np.diff(baselines)) >= 15  # stacked a line apart: they overlap horizontally


def test_a_colour_crease_below_one_8_bit_step_gets_no_amplified_panel_and_a_line_saying_why(tmp_path):
    """One corner 0.3/255 lighter: the split's largest change is a fraction of that (the bilinear crease of one
    corner's offset peaks at a quarter of it), which the PNG rounds away; a gain of thousands would paint its
    float noise. Flagged at a threshold of 0.01/255, the close-up leaves the panel out and its caption says why."""
    from affinity.report.build import ReportOptions, collect_mesh
    from affinity.report.demo import MeshInput
    from affinity.report.sections import closeups_section
    from affinity.settings import Settings

    colors = np.full((4, 3), 0.5)
    colors[2] += 0.3 / 255
    square = mesh_from_polygons("tiny", [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]], colors=colors)
    write_obj(square, tmp_path / "tiny.obj")
    settings = Settings(select=["Q102"], thresholds={"Q102": 0.01})
    result = collect_mesh(MeshInput(str(tmp_path / "tiny.obj"), "tiny.obj"), settings,
                          options=ReportOptions(max_views=1))
    (view,) = result.closeups
    assert view.place.code == "Q102"
    assert np.abs(view.images["split"] - view.images["exact"])[view.covered & view.own].max() < 1 / 255
    assert view.amplified is None and view.gain == 1.0
    assert "below one 8-bit step" in view.amplified_note
    (figure,) = closeups_section(result).data["figures"]
    assert figure["amplified"] is None and figure["amplified_note"] == view.amplified_note


def _best_overlap(image: np.ndarray, reference: np.ndarray) -> float:
    """The largest normalised cross-correlation of two (H, W) bool masks over every circular shift (FFT)."""
    a, b = image - image.mean(), reference - reference.mean()
    correlation = np.fft.ifft2(np.fft.fft2(a) * np.conj(np.fft.fft2(b))).real
    return float(correlation.max() / np.sqrt((a**2).sum() * (b**2).sum()))


def test_a_mirrored_closeup_s_glyphs_are_the_unflipped_reference_s_mirrored_on_screen():
    """The same 8 x 8 grid drawn twice from the same close-up camera (the camera depends on positions only):
    once with its uv, once with u mirrored (1 - u, every quad Q302). The glyph ink of the mirrored one matches
    the reference's ink mirrored left-right on screen (best over shifts: the glyph cells' phase differs) far
    better than the reference as it is (a symmetric glyph would match both alike)."""
    from affinity.draw.closeup import closeup
    from affinity.draw.texture import GLYPH_INK
    from affinity.report.places import Place
    from affinity.settings import Settings

    upright = grid_mesh(8)
    uv = upright.texcoords.copy()
    uv[:, 0] = 1 - uv[:, 0]
    mirrored = replace_uv(upright, uv)
    place = Place("Q302", np.array([27]), np.array([1.0]), 27, 1.0, 1.0, "warning")
    ink = {}
    for name, mesh in (("upright", replace_uv(upright, upright.texcoords)), ("mirrored", mirrored)):
        view = closeup(mesh, place, Settings(), 240, 0.5)
        ink[name] = (np.abs(view.images["exact"] - GLYPH_INK).max(axis=-1) < 0.08).astype(float)
        assert ink[name].mean() > 0.05  # big glyphs: a good share of the panel is ink
    as_mirror = _best_overlap(ink["mirrored"], ink["upright"][:, ::-1])
    as_is = _best_overlap(ink["mirrored"], ink["upright"])
    assert as_mirror > 0.55 and as_mirror > 1.2 * as_is, (as_mirror, as_is)  # measured 0.62 against 0.47
