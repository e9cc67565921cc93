"""The UV layout draws faces that share their uv once, says so, and keeps piled-up layouts cheap."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.cli import run
from helpers.quads import UNIT_UV, quad_obj, trapezoid

from affinity.loaders import load


def test_per_face_unit_uv_is_one_square_filled_by_its_flagged_share(tmp_path):
    """Reproduces the issue: per-face unit uv was a plain magenta square and cost a fragment per face per pixel."""
    from affinity.draw.shading import OVERLAY_TINT
    from affinity.report.sections import _layout_notes
    from affinity.report.uvlayout import FACE_FILL, layout_image

    path = tmp_path / "tiles.obj"
    path.write_text(quad_obj([(trapezoid(0.2 + 0.1 * k, 3 * k), UNIT_UV) for k in range(4)]))
    flagged = np.array([True, False, False, False])
    layout = layout_image(load(str(path)), flagged, 64)
    assert (layout.faces, layout.quads, layout.distinct, layout.left_out) == (4, 4, 1, 0)
    # a pixel away from the edges and the flagged face's centre mark: a quarter of the way to the flag colour
    assert np.allclose(layout.image[10, 50], FACE_FILL + 0.25 * (OVERLAY_TINT - FACE_FILL))
    assert "4 faces have only 1 distinct uv shape between them" in _layout_notes(layout)[0]


def test_piled_up_distinct_quads_stay_within_the_budget_and_flagged_ones_are_drawn(tmp_path):
    from affinity.draw.shading import OVERLAY_TINT
    from affinity.report.uvlayout import FRAGMENT_BUDGET, layout_image

    # 3 * budget quads, each covering nearly the whole square, none sharing its uv with another
    count = 3 * FRAGMENT_BUDGET
    uvs = [[(u * (1 - 0.005 * k), v * (1 - 0.005 * k)) for u, v in UNIT_UV] for k in range(count)]
    path = tmp_path / "piled.obj"
    path.write_text(quad_obj([(trapezoid(1.0, 3 * k), uv) for k, uv in enumerate(uvs)]))
    flagged = np.zeros(count, dtype=bool)
    flagged[-1] = True  # the last in file order: beyond the budget unless flagged quads go first
    layout = layout_image(load(str(path)), flagged, 64)
    area = (1 - 0.005 * np.arange(count)) ** 2 * 64 * 64  # each quad's pixels, by its closed form
    drawn_first = np.r_[area[-1], area[:-1]]  # the flagged quad, then file order
    assert layout.distinct == count
    assert layout.left_out == count - np.searchsorted(np.cumsum(drawn_first), FRAGMENT_BUDGET * 64 * 64,
                                                      side="right")
    assert np.allclose(layout.image[40, 20], OVERLAY_TINT)  # drawn over the others


@pytest.mark.slow  # two reports of 576 flagged faces
def test_place_faces_caps_every_closeup_and_no_two_share_a_face(tmp_path):
    """``--place-faces``: one connected group of 576 flagged faces is cut into places of at most N faces. The
    defect grows with y (a part repeating another's value within a tenth gets no close-up of its own)."""
    import re

    n = 24
    x, y = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0))
    x, y = x.ravel(), y.ravel()
    u, v = (x + 0.5 * x * y * y / n) / 84, y / 12  # the x*y*y term: no quad's uv is affine (u up to 3.7)
    corner = (np.arange(n)[None, :] + (n + 1) * np.arange(n)[:, None]).ravel() + 1
    quads = np.stack([corner, corner + 1, corner + n + 2, corner + n + 1], axis=1)
    path = tmp_path / "bent.obj"
    path.write_text("".join(f"v {a} {b} 0\n" for a, b in zip(x, y)) + "".join(f"vt {a} {b}\n" for a, b in zip(u, v))
                    + "".join("f " + " ".join(f"{k}/{k}" for k in quad) + "\n" for quad in quads.tolist()))
    for most in (64, 10):
        html = tmp_path / f"report{most}.html"
        done = run("report", "-q", str(path), "-o", str(html), "--place-faces", str(most))
        assert done.returncode == 0, done.stderr
        places = [set(map(int, found.split(","))) for found in re.findall(r'data-place="([^"]*)"', html.read_text())]
        assert len(places) >= 2 and all(len(place) <= most for place in places)
        assert sum(map(len, places)) == len(set().union(*places))  # no face in two close-ups


def test_the_layout_marks_only_the_faces_the_uv_rules_flag(tmp_path):
    """Three quads apart in uv: a trapezoid with square uv (Q101), a square with affine uv and a colour saddle
    (Q102: fixed in the colours, not in the UV editor) and a clean square. In the report's picture, read back
    from its PNG, only the Q101 face is in the flag colour; the colour-flagged face looks like the clean one."""
    import base64
    import io
    import json
    import re

    from PIL import Image

    corners = [[(-1, 0), (1, 0), (0.15, 1), (-0.15, 1)], [(3, 0), (5, 0), (5, 2), (3, 2)],
               [(6, 0), (8, 0), (8, 2), (6, 2)]]
    uv_squares = [(0.05, 0.3), (0.4, 0.6), (0.7, 0.9)]
    colours = [["0.5 0.5 0.5"] * 4, ["1 0 0", "0 0 0", "1 0 0", "0 0 0"], ["0.5 0.5 0.5"] * 4]
    lines = []
    for k, (quad, (lo, hi), rgb) in enumerate(zip(corners, uv_squares, colours)):
        lines += [f"v {x} {y} 0 {c}" for (x, y), c in zip(quad, rgb)]
        lines += [f"vt {u} {v}" for u, v in [(lo, lo), (hi, lo), (hi, hi), (lo, hi)]]
        lines.append("f " + " ".join(f"{4 * k + i}/{4 * k + i}" for i in range(1, 5)))
    path = tmp_path / "three.obj"
    path.write_text("\n".join(lines) + "\n")

    def cli(*args):
        return run(*args, cwd=tmp_path)

    findings = json.loads(cli("check", "--format", "json", str(path)).stdout)["findings"]
    faces = {code: {f["face"] for f in findings if f["code"] == code} for code in ("Q101", "Q102")}
    assert faces == {"Q101": {0}, "Q102": {1}}, "the fixture flags what it says"
    done = cli("report", "-q", str(path), "-o", str(tmp_path / "report.html"))
    assert done.returncode == 0, done.stderr
    figure = re.search(r'<figure data-view="uv-layout".*?</figure>', (tmp_path / "report.html").read_text(), re.S)
    size = int(re.search(r'<svg class="uv-layout"[^>]* width="(\d+)"', figure[0])[1])
    encoded = re.search(r'<image href="data:image/png;base64,([^"]+)"', figure[0])[1]
    picture = np.asarray(Image.open(io.BytesIO(base64.b64decode(encoded))).convert("RGB"), dtype=int)
    assert picture.shape == (size, size, 3)

    def pixel(u, v):  # the uv square [0, 1]^2 fills the picture, v up
        return picture[int((1 - v) * size), int(u * size)]

    uv_flagged, colour_flagged, clean, empty = pixel(0.12, 0.12), pixel(0.45, 0.45), pixel(0.75, 0.75), pixel(
        0.95, 0.05)
    assert (colour_flagged == clean).all(), "a colour finding does not mark the face in texture space"
    assert (clean != empty).any(), "the clean face is drawn"
    red, green, blue = uv_flagged
    assert red > green + 40 and blue > green + 40, f"the Q101 face is in the flag colour (magenta): {uv_flagged}"
