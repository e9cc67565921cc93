"""projective on quads with a repeated corner: the split of the one non-degenerate triangle."""

from __future__ import annotations

import numpy as np
import pytest

from render import rasterize_quads


def clip_of(xy: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(Q, 4, 2) NDC corners and (Q, 4) w -> (Q, 4, 4) clip corners at depth 0.5."""
    clip = np.empty(xy.shape[:2] + (4,))
    clip[..., :2] = xy * w[..., None]
    clip[..., 2] = 0.5 * w
    clip[..., 3] = w
    return clip


def triangles_as_pole_quads(rng, n, repeated, nudge_ulps=0):
    """n random counter-clockwise screen triangles as quads whose corner ``repeated`` repeats
    the next one (up to ``nudge_ulps`` units in the last place), with random w and attributes."""
    xy = rng.uniform(-0.9, 0.9, size=(n, 3, 2))
    cross = ((xy[:, 1] - xy[:, 0])[:, 0] * (xy[:, 2] - xy[:, 0])[:, 1]
             - (xy[:, 1] - xy[:, 0])[:, 1] * (xy[:, 2] - xy[:, 0])[:, 0])
    xy[cross < 0] = xy[cross < 0][:, ::-1]
    quad = np.empty((n, 4, 2))
    following = (repeated + 1) % 4
    quad[:, [k for k in range(4) if k != repeated]] = xy
    quad[:, repeated] = quad[:, following]
    for _ in range(nudge_ulps):
        quad[:, repeated] = np.nextafter(quad[:, repeated], np.inf)
    w = rng.uniform(0.5, 3.0, size=(n, 4))
    w[:, repeated] = w[:, following]
    return clip_of(quad, w), rng.normal(size=(n, 4, 3))


@pytest.mark.parametrize("repeated", [0, 1, 2, 3])
@pytest.mark.parametrize("nudge_ulps", [0, 1])
def test_projective_equals_split_on_repeated_corners(repeated, nudge_ulps):
    rng = np.random.default_rng(repeated + 10 * nudge_ulps)
    clip, attrs = triangles_as_pole_quads(rng, 40, repeated, nudge_ulps)
    for q in range(len(clip)):  # one quad at a time, so no quad hides another
        projective = rasterize_quads(clip[q:q + 1], attrs[q:q + 1], 96, 96, "projective")
        split = rasterize_quads(clip[q:q + 1], attrs[q:q + 1], 96, 96, "split")
        np.testing.assert_array_equal(projective.face, split.face)
        covered = split.face >= 0
        np.testing.assert_array_equal(projective.attrs[covered], split.attrs[covered])


def test_projective_equals_split_on_every_pole_quad_of_the_demo_sphere():
    """The render of the issue: ``affinity render --method projective --size 1600x1200``."""
    from affinity.draw import RenderOptions, render_mesh

    frames = {m: render_mesh(None, RenderOptions(method=m, width=1600, height=1200)) for m in ("projective", "split")}
    mesh = frames["split"].mesh
    corners = mesh.positions[mesh.corner_vertex].reshape(-1, 4, 3)
    repeated = (np.linalg.norm(corners - np.roll(corners, -1, axis=1), axis=2) == 0).any(axis=1)
    pole_faces = np.flatnonzero(repeated)
    assert len(pole_faces) == 32
    face = frames["split"].frame.face
    on_poles = np.isin(frames["split"].faces[np.maximum(face, 0)], pole_faces) & (face >= 0)
    assert on_poles.sum() > 1000
    np.testing.assert_array_equal(frames["projective"].frame.face[on_poles], face[on_poles])
    np.testing.assert_array_equal(frames["projective"].frame.attrs[on_poles], frames["split"].frame.attrs[on_poles])
