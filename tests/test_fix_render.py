"""The split render of a fixed mesh against the exact render of the original (issue 41).

The exact method intersects every pixel's ray with the original quad's bilinear patch
and interpolates its uv bilinearly: the surface and the texture the quad describes. The
fixed mesh drawn with the plain two-triangle split must show the same uv, within the
flag threshold (0.5 texels), at a close-up on the worst quad it fixed. Both frames are
compared pixel by pixel where both draw the same input face (a piece is mapped back to
the face it replaced) and that face was not left unfixed.
"""

from __future__ import annotations

import numpy as np
import pytest

from affinity import RenderOptions, render_mesh
from affinity.fix import FixSettings, plan_fix, refine_mesh
from affinity.lint import quad_texel_grid
from affinity.loaders import load
from affinity.scenes import trapezoid
from affinity.settings import Settings

THRESHOLD_TEXELS = 0.5  # Q101's flag threshold


def close_up_on(mesh, face: int) -> tuple:
    """A camera 3 face-sizes out along the face's normal, looking at its centre."""
    corners = mesh.positions[mesh.corner_vertex[mesh.face_start[face] : mesh.face_start[face + 1]]]
    centre = corners.mean(axis=0)
    normal = np.cross(corners[2] - corners[0], corners[3] - corners[1])
    normal /= np.linalg.norm(normal)
    size = np.linalg.norm(corners - centre, axis=1).max()
    return (tuple(centre + 3 * size * normal), tuple(centre), 40.0), ("z" if abs(normal[2]) < 0.9 else "y")


def uv_difference_at_worst_fixed_face(mesh, max_refine: int) -> tuple[np.ndarray, int]:
    """Texel distances between the two frames on the compared pixels, and how many pixels show the worst face."""
    plan = plan_fix(mesh, FixSettings(max_refine=max_refine))
    refined = refine_mesh(mesh, plan)
    worst = int(plan.refine_faces[np.argmax(plan.before)])
    camera, up = close_up_on(mesh, worst)
    options = {"show": "uv", "width": 200, "height": 200, "camera": camera, "up": up, "cull": False}
    fixed = render_mesh(refined.mesh, RenderOptions(method="split", **options))
    exact = render_mesh(mesh, RenderOptions(method="exact", **options))
    source_fixed = np.where(fixed.frame.face >= 0, refined.source[fixed.faces[fixed.frame.face]], -1)
    source_exact = np.where(exact.frame.face >= 0, exact.faces[exact.frame.face], -1)
    compared = (source_exact >= 0) & (source_fixed == source_exact) & ~np.isin(source_exact, plan.left_faces)
    texels = quad_texel_grid(mesh, Settings()).of(np.maximum(source_exact, 0))  # each face's own texels
    distance = np.linalg.norm((fixed.frame.attrs[..., :2] - exact.frame.attrs[..., :2]) * texels, axis=-1)
    return distance[compared], int(np.count_nonzero(compared & (source_exact == worst)))


def test_fixed_demo_trapezoid_renders_as_the_exact_original():
    distance, on_worst = uv_difference_at_worst_fixed_face(trapezoid(), max_refine=24)
    assert on_worst > 10000
    assert distance.max() <= THRESHOLD_TEXELS
    # the unfixed split is off by up to 176 texels on the same pixels
    assert distance.max() < 175.7 / 300


@pytest.mark.parametrize("name", ["gen_vase_revolution.obj", "makehuman_base_hm08.obj"])
def test_fixed_shared_meshes_render_as_the_exact_original(shared_meshes, name):
    distance, on_worst = uv_difference_at_worst_fixed_face(load(shared_meshes / name), max_refine=8)
    assert on_worst > 5000 and len(distance) > 30000
    assert distance.max() <= THRESHOLD_TEXELS
