"""An evicted texture frees its memory at once (issue 53): no reference cycle holds a decoded texture, its
pyramids or its packed texels, so dropping it from the decode cache frees it without waiting for the cyclic
garbage collector (which a folder of 4K textures outran: 4 GB for 32 meshes where the cache held 512 MiB).

The check: a weak reference to the texture and to its texel buffer is dead right after eviction, with the
collector switched off (``gc.disable``), after the lint has read the texture through every path (pyramid,
slopes, packed sampler, the visible reading).
"""

from __future__ import annotations

import gc
import weakref

import numpy as np
import pytest

from affinity.settings import Settings

pytest.importorskip("PIL")

TRAPEZOID_OBJ = ("mtllib m.mtl\nusemtl paint\nv -1 0 0\nv 1 0 0\nv 0.5 1 0\nv -0.5 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                 "vt 0 1\nf 1/1 2/2 3/3 4/4\n")


def textured_mesh(folder, name: str, seed: int):
    """An OBJ trapezoid (its uv the unit square: Q101 at every size) bound to its own 256 x 256 noise PNG."""
    from PIL import Image

    folder.mkdir()
    rng = np.random.default_rng(seed)
    Image.fromarray(rng.integers(0, 256, (256, 256, 3), dtype=np.uint8)).save(folder / f"{name}.png")
    (folder / "m.mtl").write_text(f"newmtl paint\nmap_Kd {name}.png\n")
    (folder / "m.obj").write_text(TRAPEZOID_OBJ)
    return str(folder / "m.obj"), str(folder / f"{name}.png")


def test_an_evicted_texture_is_freed_without_the_garbage_collector(tmp_path, monkeypatch):
    from affinity.pipeline.check import check_file
    from affinity.textures import decode as decoding

    first_mesh, first_png = textured_mesh(tmp_path / "a", "a", 1)
    second_mesh, _ = textured_mesh(tmp_path / "b", "b", 2)
    monkeypatch.setattr(decoding, "CACHE_BYTES", 256 * 256 * 4)  # one texture: the next evicts it
    monkeypatch.setattr(decoding, "_cache", type(decoding._cache)())
    gc.collect()
    gc.disable()
    try:
        report = check_file(first_mesh, Settings())
        assert [h.code for h in report.hits] == ["Q101"] and report.hits[0].visible is not None
        texture = decoding.decode(first_png)  # the cached one the lint read
        assert "pyramid" in vars(texture) or "slopes" in vars(texture)  # the lint built them
        texture_alive, texels_alive = weakref.ref(texture), weakref.ref(texture.texels.base or texture.texels)
        del texture, report
        check_file(second_mesh, Settings())
        assert [key[0] for key in decoding._cache] == [str((tmp_path / "b" / "b.png").resolve())]
        assert texture_alive() is None, gc.get_referrers(texture_alive())
        assert texels_alive() is None
    finally:
        gc.enable()


def test_the_cache_counts_the_pyramids_a_texture_holds(tmp_path, monkeypatch):
    """A texture read all over holds its min/max pyramid too (levels 1 and up: about 2/3 of its texels): with
    room for two textures' texels, a second texture evicts a first whose pyramid is built, not one without."""
    from affinity.textures import decode as decoding

    _, first_png = textured_mesh(tmp_path / "a", "a", 1)
    _, second_png = textured_mesh(tmp_path / "b", "b", 2)
    texel_bytes = 256 * 256 * 4
    monkeypatch.setattr(decoding, "CACHE_BYTES", 2 * texel_bytes)
    for build in (False, True):
        monkeypatch.setattr(decoding, "_cache", type(decoding._cache)())
        first = decoding.decode(first_png)
        assert first.held_bytes == texel_bytes
        if build:
            for k in range(1, first.pyramid.levels):  # boxes of 2^k texels down every row: level k, all of it
                y0 = np.arange(0, 256, 1 << k)
                first.pyramid.channel_bounds(np.zeros_like(y0), np.full_like(y0, (1 << k) - 1), y0, y0 + (1 << k) - 1)
            assert first.held_bytes == texel_bytes + 2 * sum(
                ((256 >> k) ** 2) * 4 for k in range(1, first.pyramid.levels))
        decoding.decode(second_png)
        assert (first_png in [key[0] for key in decoding._cache]) == (not build)
