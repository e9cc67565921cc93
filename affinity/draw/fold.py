"""A fold drawn as the surface it is: shaded by its own normals, lit across the fold, with the split's diagonal.

A nonplanar quad's split is two flat triangles meeting at an angle along the
diagonal 0-2; the exact surface is the bilinear patch through the four corners.
Texture lines cannot show that (the uv is affine on either triangle), but light
can: each pixel's normal is the cross product of the surface point's screen
derivatives, the surface point being the positions carried through the
rasterizer as an attribute (flat on each split triangle, curved on the patch).
The light leans from the eye toward the difference of the two triangles'
normals, so the step in brightness across the diagonal is as large as a light
that still faces the surface makes it.
"""

from __future__ import annotations

import numpy as np

#: The light leans this far (degrees) from the eye toward the triangles' normals' difference.
LIGHT_LEAN = 50.0
#: Brightness of a surface facing away from the light, and of one facing it (a two-sided Lambert term).
AMBIENT, LIT = 0.12, 0.88
FOLD_SURFACE = np.array([0.86, 0.86, 0.84])
DIAGONAL_INK = np.array([0.05, 0.35, 0.85], dtype=np.float32)


def triangle_normals(corners: np.ndarray) -> np.ndarray:
    """(Q, 2, 3) float64 unit normals of the split triangles (0, 1, 2) and (0, 2, 3) of quads ``corners``
    (Q, 4, 3); zero for a triangle without area."""
    from ..geometry import planar_quads

    # The doubled vector areas C_3, C_1 of the triangles opposite corners 3 and 1, as Q202 measures the fold.
    normals = np.transpose(planar_quads(corners).vector_areas[:, [3, 1]], (2, 1, 0))
    length = np.linalg.norm(normals, axis=-1, keepdims=True)
    return np.divide(normals, length, out=np.zeros_like(normals), where=length > 0)


def fold_light(normals: np.ndarray, toward_eye: np.ndarray) -> np.ndarray:
    """(3,) unit light direction for one quad's split triangle ``normals`` (2, 3): ``toward_eye`` (3,) unit,
    leaned ``LIGHT_LEAN`` degrees toward the part of ``normals[0] - normals[1]`` across the view.

    Lambert's terms n_a . l and n_b . l then differ by sin(LIGHT_LEAN) |d| (d that part of the difference),
    while the light stays on the eye's side. Straight from the eye when the triangles agree."""
    difference = normals[0] - normals[1]
    across = difference - (difference @ toward_eye) * toward_eye
    length = np.linalg.norm(across)
    if not length > 1e-12:
        return toward_eye
    lean = np.radians(LIGHT_LEAN)
    return np.cos(lean) * toward_eye + np.sin(lean) * across / length


def surface_normals(points: np.ndarray, face: np.ndarray) -> np.ndarray:
    """(H, W, 3) float64 unit normals of a rendered surface from its points ``points`` (H, W, 3) (NaN where
    empty) and faces ``face`` (H, W) int (-1 where empty).

    The cross product of the points' steps along a row and down a column, each the forward step where the next
    pixel shows the same face, else the backward one; NaN where neither does. Its sign follows the screen, not
    the winding: shading is two-sided."""
    def step(axis: int) -> np.ndarray:
        forward = np.full(points.shape, np.nan)
        backward = np.full(points.shape, np.nan)
        ahead = [slice(None)] * 2
        behind = [slice(None)] * 2
        ahead[axis], behind[axis] = slice(1, None), slice(None, -1)
        ahead, behind = tuple(ahead), tuple(behind)
        difference = points[ahead] - points[behind]
        same = (face[ahead] == face[behind]) & (face[ahead] >= 0)
        forward[behind] = np.where(same[..., None], difference, np.nan)
        backward[ahead] = np.where(same[..., None], difference, np.nan)
        return np.where(np.isnan(forward), backward, forward)

    normal = np.cross(step(1), step(0))
    length = np.linalg.norm(normal, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return normal / length


def shade_fold(normals: np.ndarray, covered: np.ndarray, light: np.ndarray, background: np.ndarray) -> np.ndarray:
    """(H, W, 3) float32 RGB: ``FOLD_SURFACE`` lit by ``AMBIENT + LIT |n . l|`` where ``covered`` (H, W) bool
    (n from ``normals`` (H, W, 3), mid-grey where NaN), ``background`` (3,) elsewhere."""
    with np.errstate(invalid="ignore"):
        lambert = np.abs(normals @ light)
    brightness = AMBIENT + LIT * np.where(np.isnan(lambert), 0.5, lambert)
    image = np.where(covered[..., None], FOLD_SURFACE * brightness[..., None], background)
    return image.astype(np.float32)


def draw_diagonals(image: np.ndarray, face: np.ndarray, ends: np.ndarray, faces: np.ndarray,
                   matrix: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pixels of ``image`` (H, W, 3), painted ``DIAGONAL_INK`` in place, where the segments
    ``ends`` (D, 2, 3) (each quad's corners 0 and 2, world space) cross their own face ``faces`` (D,) of
    ``face`` (H, W) int; ``matrix`` (4, 4) the camera's. Sampled at half-pixel steps along each segment."""
    from render import to_clip

    height, width = face.shape
    clip = to_clip(ends, matrix)  # (D, 2, 4)
    if not (clip[..., 3] > 0).all():
        keep = (clip[..., 3] > 0).all(axis=1)
        clip, faces = clip[keep], faces[keep]
    pixel = np.stack([(clip[..., 0] / clip[..., 3] + 1) * width / 2,
                      (1 - clip[..., 1] / clip[..., 3]) * height / 2], axis=-1)  # (D, 2, 2) x, y
    length = np.linalg.norm(pixel[:, 1] - pixel[:, 0], axis=-1)
    samples = np.maximum(np.ceil(2 * length).astype(np.int64), 1) + 1
    owner = np.repeat(np.arange(len(pixel)), samples)
    t = (np.arange(samples.sum()) - np.repeat(np.cumsum(samples) - samples, samples)) / np.repeat(samples - 1, samples)
    xy = pixel[owner, 0] + t[:, None] * (pixel[owner, 1] - pixel[owner, 0])
    column, row = np.floor(xy[:, 0]).astype(np.int64), np.floor(xy[:, 1]).astype(np.int64)
    inside = (column >= 0) & (column < width) & (row >= 0) & (row < height)
    row, column, owner = row[inside], column[inside], owner[inside]
    own = face[row, column] == faces[owner]
    drawn = np.zeros(face.shape, dtype=bool)
    drawn[row[own], column[own]] = True
    image[drawn] = DIAGONAL_INK
    return drawn
