"""Close-ups show their place: counted on the report's own HTML against an independent face-id render.

Each close-up figure carries its camera (``data-camera``, ``data-up``), its place's faces
(``data-place``) and the faces it draws (``data-drawn``). The test re-renders those faces' ids
with ``render_mesh`` at that camera and counts the place's pixels, and decodes the split and exact
panels from the page to count the pixels where they differ.
"""

from __future__ import annotations

import base64
import io
import re
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run

from affinity.loaders import load

pytestmark = pytest.mark.slow  # a report of every shared mesh

#: The pixels a close-up's place and its worst face must each cover, and the share of a uv / colour close-up
#: where split and exact differ.
PLACE_PIXELS = 300
DIFFERENT_SHARE = 0.01
FIGURE = re.compile(r'<figure class="closeup"(?P<attrs>[^>]*)>(?P<body>.*?)</figure>', re.S)
ATTRIBUTE = re.compile(r'data-([a-z-]+)="([^"]*)"')
PANEL = re.compile(r'<img src="data:image/png;base64,([^"]+)" alt="(\w+), face')


def left_handed_copy(source: Path, target: Path) -> None:
    """Write ``source`` OBJ with each face's corner order reversed (clockwise winding, normals inward)."""
    lines = []
    for line in source.read_text(encoding="utf-8").splitlines():
        words = line.split()
        if words and words[0] == "f":
            line = " ".join(["f", *reversed(words[1:])])
        lines.append(line)
    target.write_text("\n".join(lines) + "\n", encoding="utf-8")


def report_figures(mesh: Path, html: Path) -> list[dict]:
    """Run ``affinity report`` on ``mesh``; each close-up figure's data attributes and decoded panels."""
    done = run("report", "-q", str(mesh), "-o", str(html))
    assert done.returncode == 0, done.stderr
    return page_figures(html)


def page_figures(html: Path) -> list[dict]:
    """Each close-up figure of the report page ``html``: its data attributes and decoded panels."""
    from PIL import Image

    figures = []
    for match in FIGURE.finditer(html.read_text(encoding="utf-8")):
        figure = dict(ATTRIBUTE.findall(match["attrs"]))
        figure["panels"] = {name: np.asarray(Image.open(io.BytesIO(base64.b64decode(data))).convert("RGB"))
                            for data, name in PANEL.findall(match["body"])}
        figures.append(figure)
    return figures


def faces_of(ranges: str) -> np.ndarray:
    """``"0-4,7"`` -> [0, 1, 2, 3, 4, 7]."""
    faces = []
    for part in filter(None, ranges.split(",")):
        first, _, last = part.partition("-")
        faces.extend(range(int(first), int(last or first) + 1))
    return np.array(faces, dtype=np.int64)


def place_pixels(mesh, figure: dict, size: int, faces: str | None = None) -> int:
    """The pixels the figure's place (or ``faces``, ranges as in ``data-place``) covers in a depth-tested
    face-id render of its drawn faces at its camera."""
    from affinity.draw.drawing import RenderOptions, render_mesh
    from affinity.draw.faces import face_subset

    numbers = [float(x) for x in figure["camera"].split(",")]
    camera = (tuple(numbers[:3]), tuple(numbers[3:6]), numbers[6])
    drawn = faces_of(figure["drawn"])
    result = render_mesh(face_subset(mesh, drawn), RenderOptions(method="split", show="shaded", width=size,
                                                                  height=size, camera=camera, up=figure["up"]))
    face = result.frame.face
    mesh_face = np.where(face >= 0, drawn[result.faces[np.maximum(face, 0)]], -1)
    return int(np.isin(mesh_face, faces_of(faces or figure["place"])).sum())


def check_figures(mesh_path: Path, figures: list[dict]) -> None:
    from affinity.rules import RULES

    mesh = load(str(mesh_path))
    seen: set[int] = set()
    for figure in figures:
        label = f"{mesh_path.name} face {figure['face']} {figure['rule']}"
        size = figure["panels"]["split"].shape[0]
        assert place_pixels(mesh, figure, size) >= PLACE_PIXELS, label
        assert place_pixels(mesh, figure, size, figure["face"]) >= PLACE_PIXELS, label  # the face it is named by
        place = set(faces_of(figure["place"]).tolist())
        assert len(place) <= 64 and not place & seen, label
        seen |= place
        if RULES[figure["rule"]].attribute in ("texcoords", "colors") and "exact" in figure["panels"]:
            split, exact = figure["panels"]["split"].astype(int), figure["panels"]["exact"].astype(int)
            assert (np.abs(split - exact).max(axis=2) > 0).mean() >= DIFFERENT_SHARE, label


def test_a_left_handed_mesh_is_seen_from_outside(shared_meshes, tmp_path):
    """Reproduces the issue: with clockwise faces the camera followed the inward normal and the place covered
    0 pixels of its close-up."""
    flipped = tmp_path / "spot_left_handed.obj"
    left_handed_copy(shared_meshes / "spot_control_mesh.obj", flipped)
    figures = report_figures(flipped, tmp_path / "report.html")
    assert figures
    check_figures(flipped, figures)


@pytest.mark.parametrize("name", ["spot_control_mesh.obj", "osd_catmark_bishop.obj", "osd_catmark_torus.obj",
                                  "osd_catmark_car.obj", "gen_vase_revolution.obj",
                                  "tinyobjloader_cube_vertexcol.obj", "gen_uv_sphere_64x32.obj",
                                  "osd_catmark_nonquads.obj",
                                  "makehuman_base_hm08.obj", "gen_spot_cc4.obj"])
def test_every_closeup_of_a_shared_mesh_shows_its_place(shared_meshes, report_of, name):
    path = shared_meshes / name
    done, page = report_of(path)
    assert done.returncode == 0, done.stderr
    check_figures(path, page_figures(page))
