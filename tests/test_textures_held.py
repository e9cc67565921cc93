"""Held textures (affinity.textures.held): texels another program decoded, read as a decoded file is.

The truth is the file itself: the same texels written as a PNG and decoded by Pillow give the same texel unit
and the same visible reading (C) as when they are held under a key that is no file.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from affinity.lint import lint_mesh
from affinity.loaders import load
from affinity.loaders.imagesize import ImageHeader
from affinity.settings import Settings
from affinity.textures.decode import DecodedTexture, decode, why_not_decoded
from affinity.textures.held import PREFIX, held_texture, holding

PIL = pytest.importorskip("PIL.Image")

TRAPEZOID = "mtllib m.mtl\nusemtl m\nv 0 0 0\nv 2 0 0\nv 1.5 1 0\nv 0.5 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" \
            "f 1/1 2/2 3/3 4/4\n"


def held(key: str, texels: np.ndarray) -> DecodedTexture:
    """``texels`` (H, W, 3) uint8 as a held texture: four bytes a texel, as decode gives them."""
    height, width = texels.shape[:2]
    padded = np.full((height, width, 4), 255, dtype=np.uint8)
    padded[..., :3] = texels
    padded.flags.writeable = False
    return DecodedTexture(key, ImageHeader(width, height, "PNG"), padded, 3)


def test_a_held_texture_reads_as_its_png_does(tmp_path):
    texels = np.random.default_rng(0).integers(0, 256, (24, 40, 3), dtype=np.uint8)
    PIL.fromarray(texels).save(tmp_path / "t.png")
    (tmp_path / "m.mtl").write_text("newmtl m\nmap_Kd t.png\n")
    (tmp_path / "q.obj").write_text(TRAPEZOID)
    mesh = load(tmp_path / "q.obj")
    settings = Settings(select=["Q101"], thresholds={"Q101": 0.0})
    (from_file,) = lint_mesh(mesh, settings)
    key = PREFIX + "t"
    maps = {name: [replace(m, path=key) for m in found] for name, found in mesh.material_maps.items()}
    in_memory = replace(mesh, material_maps=maps, material_textures={})
    with holding({key: held(key, texels)}):
        (from_memory,) = lint_mesh(in_memory, settings)
        assert decode(key) is held_texture(key) and why_not_decoded(key) is None
    np.testing.assert_array_equal(from_memory.values, from_file.values)  # C, through the same texels
    np.testing.assert_array_equal(from_memory.visible.shifts, from_file.visible.shifts)  # at 40 x 24 texels
    assert from_file.values[0] > 8
    assert held_texture(key) is None  # let go after the block
    with pytest.raises(ValueError, match="must start with"):
        with holding({str(tmp_path / "t.png"): held("x", texels)}):
            pass


def test_holding_a_key_again_gives_the_outer_texture_back_after():
    key = PREFIX + "nested"
    outer, inner = held(key, np.zeros((2, 2, 3), np.uint8)), held(key, np.ones((2, 2, 3), np.uint8))
    with holding({key: outer}):
        with holding({key: inner}):
            assert held_texture(key) is inner
        assert held_texture(key) is outer
    assert held_texture(key) is None
