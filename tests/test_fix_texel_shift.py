"""The fix refines a quad read through its texture by the texel shift, never by the colour value C.

Q101's visible reading replaces a finding's value by C (1/255 steps) and keeps the shift (texels) beside it
(design.md, "One findings table": consumers that need the shift read ``shift``). How far a quad is refined
depends on its uv alone: the same quad with and without a texture, counted in the same texels, is cut into
the same n x n pieces; the texture only decides whether it is fixed at all (its level).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from affinity.fix import FixSettings, plan_fix
from affinity.lint import lint_mesh
from affinity.loaders import load
from affinity.settings import Settings

PIL = pytest.importorskip("PIL.Image")

#: Two trapezoids carrying unit uv squares; the second is nearly a parallelogram (a small shift).
OBJ = """mtllib m.mtl
usemtl m
v 0 0 0
v 2 0 0
v 1.5 1 0
v 0.5 1 0
v 3 0 0
v 5 0 0
v 4.95 1 0
v 3.05 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
f 1/1 2/2 3/3 4/4
f 5/1 6/2 7/3 8/4
"""


def test_a_textured_quad_is_refined_as_far_as_its_shift_needs(tmp_path):
    texels = np.zeros((64, 64, 3), dtype=np.uint8)
    texels[:, ::2] = 255  # one-texel stripes: any shift across them shows (C far above the shift in texels)
    PIL.fromarray(texels).save(tmp_path / "stripes.png")
    (tmp_path / "m.mtl").write_text("newmtl m\nmap_Kd stripes.png\n")
    (tmp_path / "textured.obj").write_text(OBJ)
    (tmp_path / "bare.obj").write_text(OBJ.replace("mtllib m.mtl\n", ""))
    settings = Settings(texture_size=64)
    fix = FixSettings(lint=settings, level="info", max_refine=16)
    textured, bare = (plan_fix(load(tmp_path / name), fix) for name in ("textured.obj", "bare.obj"))
    assert textured.refine_faces.tolist() == bare.refine_faces.tolist() == [0, 1]
    assert textured.refine_n.tolist() == bare.refine_n.tolist()
    # The plan's readings are the shift before and after, in texels, as its units say.
    np.testing.assert_allclose(textured.before, bare.before)
    np.testing.assert_allclose(textured.after, bare.after)
    assert textured.units.tolist() == ["texels", "texels"]
    (hits,) = lint_mesh(load(tmp_path / "textured.obj"), replace(settings, select=["Q101"]))
    assert (hits.values > 50).all()  # the colour values (C), which must not set n
