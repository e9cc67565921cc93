"""Wrap modes as the material authors them (issue 55): a texture that clamps is not read as repeating.

The quads of :mod:`helpers.usd_studio` with their uv moved one unit along u (to 1.0-1.1): repeating, they
read the stripes as at 0.0-0.1 (the same C as the unmoved mesh); clamped, every sample reads the last
column, and the stripes vary along u only, so C = 0 (closed form); mirrored, they read the stripes at
0.9-1.0 reversed, the same C as the mesh with u -> 2 - u read repeating.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run
from helpers.usd_stages import COUNTS, INDICES, POINTS, ST
from helpers.usd_studio import stripes

from affinity.textures.wrapping import wrapped_uv


def q101(path: Path) -> list[tuple[int, float]]:
    result = run("check", "--no-cache", "--isolated", "--format", "json", "--select", "Q101", str(path))
    assert result.returncode in (0, 1), result.stderr
    return [(f["face"], f["value"]) for f in json.loads(result.stdout)["findings"]]


def obj_with(folder: Path, name: str, uv, option: str = "") -> Path:
    """The studio mesh as ``name``.obj with uv ``uv`` and an MTL naming ``stripes.png`` with ``option``."""
    from PIL import Image

    if not (folder / "stripes.png").exists():
        Image.fromarray(stripes()).save(folder / "stripes.png")
    (folder / f"{name}.mtl").write_text(f"newmtl m\nmap_Kd {option} stripes.png\n")
    lines = [f"mtllib {name}.mtl", "usemtl m", *(f"v {x} {y} {z}" for x, y, z in POINTS),
             *(f"vt {u!r} {v!r}" for u, v in uv)]
    corner = 0
    for n in COUNTS:
        lines.append("f " + " ".join(f"{INDICES[corner + k] + 1}/{corner + k + 1}" for k in range(n)))
        corner += n
    (folder / f"{name}.obj").write_text("\n".join(lines) + "\n")
    return folder / f"{name}.obj"


def test_a_clamped_map_reads_the_edge_and_a_repeating_one_the_stripes(tmp_path):
    moved = [(u + 1.0, v) for u, v in ST]
    unmoved = q101(obj_with(tmp_path, "unmoved", ST))
    assert unmoved[0][1] > 8  # the stripes show at face 0
    assert q101(obj_with(tmp_path, "repeat", moved)) == unmoved
    assert [value for _, value in q101(obj_with(tmp_path, "clamp", moved, "-clamp on"))] == [0.0] * len(unmoved)


def test_mirror_wrapping_reads_the_reflected_texture():
    uv = np.array([[1.2, 0.3], [-0.25, 1.75], [2.6, 0.5]])
    moved, black = wrapped_uv(uv, ("mirror", "mirror"), (512, 512))
    assert black is None
    assert np.allclose(moved, [[0.8, 0.3], [0.25, 0.25], [0.6, 0.5]])


def test_a_black_border_reads_zero_outside_and_clamps_inside():
    moved, black = wrapped_uv(np.array([[1.2, 0.5], [0.0, 0.5], [0.5, 0.5]]), ("black", "repeat"), (4, 4))
    assert black.tolist() == [True, False, False]
    assert moved[1].tolist() == [0.125, 0.5]  # the first texel's centre: clamp to edge inside


def test_materialx_address_modes_clamp_the_studio_asset(tmp_path):
    """The MaterialX look of the studio asset with ``uaddressmode = clamp`` and the mesh's uv moved past 1:
    every Q101 reads C = 0, where the same asset repeating reads the stripes."""
    pytest.importorskip("pxr", reason="needs the usd extra (usd-core)")
    from helpers.usd_studio import studio_asset
    from pxr import Sdf

    stage = studio_asset(tmp_path)
    geometry = Sdf.Layer.FindOrOpen(str(tmp_path / "assets/Piece/Piece_geom.usd"))
    geometry.GetAttributeAtPath("/Piece/Geom/Render.primvars:st").default = [(u + 1.0, v) for u, v in ST]
    geometry.Save()
    repeating = q101(stage)
    assert max(value for _, value in repeating) > 8
    material = tmp_path / "assets/Piece/Piece_mat.mtlx"
    material.write_text(material.read_text().replace(
        'colorspace="srgb_texture" />',
        'colorspace="srgb_texture" />\n      <input name="uaddressmode" type="string" value="clamp" />'))
    assert [value for _, value in q101(stage)] == [0.0] * len(repeating)
