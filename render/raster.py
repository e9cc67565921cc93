"""``rasterize_quads``: clip-space quads in, a ``Frame`` out.

The pipeline, all of it vectorised over quads, triangles, rows or fragments:

1. Every quad becomes the two triangles of its 0-2 split, (0, 1, 2) and
   (0, 2, 3). Each gets its homogeneous determinant (its orientation, also for
   corners behind the eye) and its interpolation planes (``render.planes``):
   attributes, 1/w and depth as affine functions of the pixel.
2. Triangles outside the view are dropped, the rest are clipped in clip space
   against the near and far planes and a wide guard band (``render.clip``), so
   corners behind the eye (w < 0) or on the eye plane (w = 0) never reach the
   division by w. Attributes and depth do not come from the clipped corners
   but from the original triangle and quad.
3. The clipped triangles are snapped to fixed point and covered pixels are
   found as exact integer spans per row (``render.spans``), with the top-left
   fill rule.
4. Coverage per method: ``split`` and ``projective`` draw the two triangles.
   ``mvc``, ``bilinear`` and ``exact`` fill the quad itself: a pixel is
   covered when it is in exactly one of the two triangles (their exclusive
   or). For a convex quad, or a concave one whose reflex corner is 0 or 2,
   the triangles do not overlap and this is their union; for a quad concave
   at corner 1 or 3 (the second triangle lies inside the first, oppositely
   wound) and for a bow-tie it removes the overlap. This is the non-zero
   winding rule of the outline 0-1-2-3, the region of HT04 eq. 12; it is
   evaluated on the visible part of each triangle, i.e. with the homogeneous
   edge functions of Olano & Greer, as the clarifications ask for quads with
   corners at w <= 0. With culling a covered pixel faces the way its triangle
   does, so a bow-tie keeps its front-facing lobe only.
5. Depth: every fragment's depth is the NDC z of the 3-D split triangle that
   covers it, for every method. For planar quads that is the plane, the very
   surface that mvc (HT04 eq. 9, whose depth z(v) is the plane's), bilinear
   and exact describe; for a non-planar quad the mvc/bilinear/exact
   attributes are painted on the split surface (exact's attributes are those
   of the patch point on the pixel's ray, its depth the split's). So
   visibility never depends on the method, which is what lets a per-quad
   method array give, on each quad, exactly the pixels of that method's own
   render. Depth test "less"; ties go to the earlier quad (``render.depth``).
6. Attributes are evaluated for the winning fragment of each pixel only (a
   visibility buffer): from the triangle's planes for split and projective,
   from the per-method corner weights of ``render.methods`` and the quad's
   clip-space corners for mvc, bilinear and exact.

Memory is bounded by drawing the quads in batches of ``BATCH_QUADS`` (each set
up and drawn whole, its winners kept where they are strictly nearer than what
earlier batches left: the depth test "less", ties to the earlier quad), each
batch's image in bands of rows holding about ``batch_fragments`` fragments
(estimated from the triangles' areas), and by setting quads up in chunks of
``SETUP_QUADS``. A scene whose fragments (overdraw) exceed
``MAX_FRAGMENTS``, or whose single row holds more than ``MAX_ROW_FRAGMENTS``
(a row is never split), stops with an ``OverBudget`` error (a ValueError) saying so before it is drawn:
ten million triangles stacked on one spot would otherwise take hours. These
Python loops are the only ones: their trip counts grow with the fragment and
quad counts divided by batch sizes, never per quad or per pixel, and small
batches keep the temporaries in cache. (Bands are independent -- every triangle touching a
band is drawn into it -- but drawing them in threads was measured slower
here: with arrays this small NumPy spends much of its time holding the GIL.)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from render.clip import clip_triangles, plane_distances
from render.depth import nearest_fragments
from render.frame import Frame
from render.methods import (
    METHODS,
    PLANE_METHODS,
    QUAD_COVERAGE,
    WEIGHTS,
    projective_corner_weights,
)
from render.planes import evaluate, triangle_planes
from render.spans import (
    MAX_SIZE,
    ScreenTriangles,
    expand_ranges,
    guard_planes,
    row_spans,
    snap_triangles,
)

TRIANGLE_CORNERS = np.array([[0, 1, 2], [0, 2, 3]])
NEAR_FAR_PLANES = np.array([[0, 0, 1.0, 1.0], [0, 0, -1.0, 1.0]])  # -w <= z <= w
SCREEN_PLANES = np.array([[-1.0, 0, 0, 1], [1.0, 0, 0, 1], [0, -1.0, 0, 1], [0, 1.0, 0, 1]])
DEFAULT_BATCH_FRAGMENTS = 1 << 16
SETUP_QUADS = 1 << 13  # quads set up at once: their temporaries stay small enough to be reused
#: Quads set up and drawn at once: a batch's scene takes about 600 bytes a quad (planes, corners,
#: screen triangles), so 2^19 quads hold some 300 MB whatever the mesh's size.
BATCH_QUADS = 1 << 19
#: Fragments a render may draw in all (a few seconds: 30 million a second measured on a busy
#: 2-core machine): 32 times the pixels of a 4K image. More means quads stacked many deep.
MAX_FRAGMENTS = 1 << 28
#: Fragments one row of one batch may hold (a band is never narrower than a row): some 1 GB of
#: per-fragment temporaries.
MAX_ROW_FRAGMENTS = 1 << 24
SHADE_BLOCK = 1 << 14  # pixels shaded at once: temporaries stay in cache


def rasterize_quads(
    clip,
    attrs,
    width,
    height,
    method="split",
    *,
    cull_backfaces=False,
    batch_fragments=DEFAULT_BATCH_FRAGMENTS,
) -> Frame:
    """Rasterize quads given by their clip-space corners.

    Parameters
    ----------
    clip : (Q, 4, 4) float
        Corners (x, y, z, w) in clip space, in outline order. A triangle is
        passed as a quad with a repeated last corner.
    attrs : (Q, 4, K) float
        Per-corner attributes to interpolate (K may be 0).
    width, height : int
        Image size in pixels, from 1 to 65536.
    method : str or (Q,) sequence of str
        ``"split"``, ``"mvc"``, ``"bilinear"``, ``"projective"`` or
        ``"exact"`` (the float64 ray / bilinear-patch reference) for all
        quads, or one name per quad (the hybrid render); see
        ``render.methods``.
    cull_backfaces : bool
        Drop fragments of triangles wound clockwise on screen (NDC y up).
    batch_fragments : int
        About how many fragments to hold in memory at once.

    Returns
    -------
    Frame
        ``face`` (H, W) int64 (-1 empty), ``attrs`` (H, W, K) float64 (NaN
        empty), ``depth`` (H, W) float64 (NDC z, inf empty), and the
        ``fragments`` count. Attributes are perspective-correct for split,
        mvc and exact, screen-space for bilinear and projective.

    Examples
    --------
    >>> square = [[[-1, -1, 0, 1], [1, -1, 0, 1], [1, 1, 0, 1], [-1, 1, 0, 1]]]
    >>> uv = [[[0, 0], [1, 0], [1, 1], [0, 1]]]
    >>> frame = rasterize_quads(square, uv, 4, 2, method="mvc")
    >>> frame.face.tolist()
    [[0, 0, 0, 0], [0, 0, 0, 0]]
    >>> frame.attrs[0, :, 0].round(12).tolist()  # u at the column centres
    [0.125, 0.375, 0.625, 0.875]
    """
    clip, attrs, method_of_quad, names = _checked_input(clip, attrs, width, height, method)
    if not batch_fragments >= 1:
        raise ValueError(f"batch_fragments must be at least 1, got {batch_fragments!r}")
    frame = Frame.empty(height, width, attrs.shape[2])
    frame.fragments = 0
    for first in range(0, clip.shape[0], BATCH_QUADS):
        batch = slice(first, first + BATCH_QUADS)
        scene = _Scene.build(clip[batch], attrs[batch], method_of_quad[batch], names, width, height, cull_backfaces)
        scene.first_quad = first
        frame.fragments += sum(_draw_band(frame, scene, *band)
                               for band in scene.bands(batch_fragments, MAX_FRAGMENTS - frame.fragments))
    return frame


@dataclass
class _Scene:
    """Everything set up once per call, before the bands are drawn.

    Quads: ``corners`` (4, 4, Q) float64 clip x, y, z, w (component, corner,
    quad); ``attrs`` (4, K, Q) (corner, channel, quad); ``method_of_quad``
    (Q,) int index into ``names``. Split triangles (index 2 q + half):
    ``attribute_planes`` (3, K + 1, 2Q), the interpolation planes
    (``render.planes``) of rho a / w for the K attributes and of rho / w
    (rho = 1 except for projective quads), and ``depth_planes`` (3, 2Q), of
    NDC depth (each contiguous: gathers from views are slower); ``orientation`` (2Q,)
    the sign of the homogeneous determinant (+1 counter-clockwise in NDC).
    Screen triangles (the clipped, snapped pieces): ``screen``, ``parent``
    (T,) split-triangle index, ``exclusive`` (T,) True for pieces of quads
    covered by the exclusive or of their two triangles.
    """

    width: int
    height: int
    cull_backfaces: bool
    names: list
    method_of_quad: np.ndarray
    corners: np.ndarray
    attrs: np.ndarray
    attribute_planes: np.ndarray
    depth_planes: np.ndarray
    orientation: np.ndarray
    screen: ScreenTriangles
    parent: np.ndarray
    exclusive: np.ndarray
    first_quad: int = 0  # the index of the batch's first quad among all the call's quads

    @classmethod
    def build(cls, clip, attrs, method_of_quad, names, width, height, cull_backfaces):
        fills_quad = np.isin(np.asarray(names), list(QUAD_COVERAGE))[method_of_quad]
        n_quads = clip.shape[0]
        rho = np.ones((n_quads, 4, 1))
        if "projective" in names:
            projective = method_of_quad == names.index("projective")
            rho[projective, :, 0] = projective_corner_weights(clip[projective])
        planes = np.empty((3, attrs.shape[2] + 2, 2 * n_quads))
        orientation = np.empty(2 * n_quads)
        # Set up in chunks of quads so that the per-triangle temporaries stay small.
        screens, parents, exclusives = [], [np.zeros(0, np.int64)], [np.zeros(0, bool)]
        for start in range(0, n_quads, SETUP_QUADS):
            part = slice(start, start + SETUP_QUADS)
            triangles = slice(2 * start, 2 * start + 2 * clip[part].shape[0])
            planes[:, :, triangles], orientation[triangles], screen, parent, exclusive = _triangle_setup(
                clip[part], attrs[part], rho[part], fills_quad[part], width, height, cull_backfaces
            )
            screens.append(screen)
            parents.append(parent + 2 * start)
            exclusives.append(exclusive)
        return cls(
            width=width,
            height=height,
            cull_backfaces=cull_backfaces,
            names=names,
            method_of_quad=method_of_quad,
            corners=np.ascontiguousarray(clip.transpose(2, 1, 0)),
            attrs=np.ascontiguousarray(attrs.transpose(1, 2, 0)),
            attribute_planes=np.ascontiguousarray(planes[:, :-1]),
            depth_planes=np.ascontiguousarray(planes[:, -1]),
            orientation=orientation,
            screen=ScreenTriangles.concatenate(screens),
            parent=np.concatenate(parents),
            exclusive=np.concatenate(exclusives),
        )

    def bands(self, batch_fragments, max_fragments=MAX_FRAGMENTS):
        """Yield (row_start, row_stop, screen-triangle indices) per band of rows.

        Bands hold about ``batch_fragments`` fragments each by the estimate of
        ``ScreenTriangles.size`` spread evenly over each triangle's rows; a
        single row is never split. Triangle indices are increasing. OverBudget,
        before any band, when the estimate exceeds ``max_fragments`` or one row
        :data:`MAX_ROW_FRAGMENTS`.
        """
        screen, height = self.screen, self.height
        if screen.row0.size == 0:
            return
        per_row = screen.size / (screen.row1 - screen.row0 + 1)
        spread = np.bincount(screen.row0, per_row, height + 1) - np.bincount(
            screen.row1 + 1, per_row, height + 1
        )
        row_fragments = np.cumsum(spread)[:height]
        _check_overdraw(row_fragments, max_fragments, self.width)
        cumulative = np.cumsum(row_fragments)
        cuts = np.searchsorted(
            cumulative, np.arange(batch_fragments, cumulative[-1], batch_fragments), side="right"
        )
        starts = np.unique(np.concatenate([[0], cuts[cuts < height]]))
        first = np.searchsorted(starts, screen.row0, side="right") - 1
        last = np.searchsorted(starts, screen.row1, side="right") - 1
        owner, rank = expand_ranges(last - first + 1)
        band = first[owner] + rank
        order = np.argsort(band, kind="stable")
        members, band = owner[order], band[order]
        limits = np.searchsorted(band, np.arange(starts.size + 1))
        stops = np.append(starts[1:], height)
        for b in range(starts.size):
            if limits[b] < limits[b + 1]:
                yield int(starts[b]), int(stops[b]), members[limits[b] : limits[b + 1]]


class OverBudget(ValueError):
    """A scene that would take more time or memory than a render's budgets allow."""


def _check_overdraw(row_fragments: np.ndarray, max_fragments: float, width: int) -> None:
    """OverBudget when the fragments estimated per row, (H,) float64, are more than a render draws."""
    total, widest = float(row_fragments.sum()), float(row_fragments.max())
    if total > max_fragments or widest > MAX_ROW_FRAGMENTS:
        raise OverBudget(
            f"the quads would draw about {total:.3g} fragments ({total / (width * len(row_fragments)):.3g} times the "
            f"image's pixels, up to {widest:.3g} in one row): over the render's budget of {MAX_FRAGMENTS:.3g} "
            f"({MAX_ROW_FRAGMENTS:.3g} a row); the faces are stacked many deep: render a part of the mesh")


def _triangle_setup(clip, attrs, rho, fills_quad, width, height, cull_backfaces):
    """Split, plane setup, culling, clipping and snapping for quads clip (Q, 4, 4).

    The attribute planes interpolate rho a and rho, rho (Q, 4, 1) being 1
    except for projective quads. Returns planes (3, K + 2, 2Q) and
    orientation (2Q,) of the split triangles (index 2 q + half), and for the
    screen triangles they become: the ``ScreenTriangles``, their parent split
    triangle (increasing) and whether their quad is covered by the exclusive
    or of its triangles.
    """
    tri = _split(clip)
    values = np.concatenate([_split(rho * attrs), _split(rho), tri[2:3]])  # rho a, rho, z
    det, planes = triangle_planes(tri, values, width, height)
    orientation = np.sign(det)

    exclusive = np.repeat(fills_quad & (orientation[0::2] * orientation[1::2] < 0), 2)
    outside = plane_distances(tri, SCREEN_PLANES) < 0
    off_screen = (outside[:, 0] & outside[:, 1] & outside[:, 2]).any(axis=0)
    # det = 0: degenerate or seen edge-on; non-finite planes: det underflowed.
    finite = np.isfinite(planes[:, -2:]).all(axis=(0, 1))
    drawn = (orientation != 0) & finite & ~off_screen
    if cull_backfaces:
        # Exclusive-or quads are culled per fragment, after the overlap is removed.
        drawn &= (orientation > 0) | exclusive
    candidates = np.flatnonzero(drawn)

    pieces, parent = clip_triangles(
        np.take(tri, candidates, axis=2), np.vstack([NEAR_FAR_PLANES, guard_planes(width, height)])
    )
    w = pieces[3]
    in_front = np.flatnonzero((w[0] > 0) & (w[1] > 0) & (w[2] > 0))
    keep = in_front[np.argsort(parent[in_front], kind="stable")]  # draw order = quad order, for depth ties
    parent = candidates[parent[keep]]
    screen, kept = snap_triangles(np.take(pieces, keep, axis=2), orientation[parent], width, height)
    parent = parent[kept]
    return planes, orientation, screen, parent, exclusive[parent]


def _split(corner_values) -> np.ndarray:
    """Per-corner values (Q, 4, C) of quads as values of their split triangles,
    component-major (C, 3, 2Q): triangle 2 q is (0, 1, 2) of quad q, 2 q + 1 is (0, 2, 3)."""
    by_component = np.ascontiguousarray(corner_values.transpose(2, 1, 0))  # (C, 4, Q)
    out = np.empty(by_component.shape[:1] + (3, by_component.shape[2], 2))
    for half, corners in enumerate(TRIANGLE_CORNERS):
        out[..., half] = by_component[:, corners]
    return out.reshape(out.shape[0], 3, 2 * out.shape[2])


def _draw_band(frame, scene, row_start, row_stop, selection) -> int:
    """Draw the screen triangles ``selection`` into rows [row_start, row_stop) of
    ``frame``; return the number of fragments."""
    width = scene.width
    screen = scene.screen
    exclusive = scene.exclusive[selection]
    # Tags are positions in ``selection`` (draw order); exclusive-or pieces
    # are generated last so that their fragments form one tail.
    tag_order = np.concatenate([np.flatnonzero(~exclusive), np.flatnonzero(exclusive)])
    tri = selection[tag_order]
    first_row = np.maximum(screen.row0[tri], row_start)
    rows = np.minimum(screen.row1[tri], row_stop - 1) - first_row + 1
    owner, rank = expand_ranges(rows)
    pair_tri, pair_row = tri[owner], first_row[owner] + rank
    c_lo, c_hi = row_spans(screen, pair_tri, pair_row, width)
    length = np.maximum(c_hi - c_lo + 1, 0)

    z0, zc, zr = np.take(scene.depth_planes, scene.parent[pair_tri], axis=1)
    # Fragment k of a span (row, c_lo .. c_hi) is pixel c_lo + k; every per-fragment array is one
    # np.repeat of a per-span value, plus k.
    k = np.arange(length.sum()) - np.repeat(np.cumsum(length) - length, length)
    pixel = np.repeat((pair_row - row_start) * width + c_lo, length)
    pixel += k
    depth = np.repeat(zc, length)
    depth *= k
    depth += np.repeat(z0 + zr * pair_row + zc * c_lo, length)
    tag = np.repeat(tag_order[owner], length)

    if exclusive.any():
        tail = length[: rows[: np.count_nonzero(~exclusive)].sum()].sum()
        keep = _exclusive_or(scene, selection, pixel[tail:], tag[tail:], (row_stop - row_start) * width)
        keep = np.concatenate([np.ones(tail, dtype=bool), keep])
        pixel, depth, tag = pixel[keep], depth[keep], tag[keep]
    np.clip(depth, -1.0, 1.0, out=depth)

    covered, winner = nearest_fragments(pixel, depth, tag, (row_stop - row_start) * width, selection.size)
    triangle = scene.parent[selection[winner]]
    for block in range(0, covered.size, SHADE_BLOCK):
        part = slice(block, block + SHADE_BLOCK)
        row = covered[part] // width  # floor_divide and a product: np.divmod is several times slower
        col = covered[part] - row * width
        _shade(frame, scene, row + row_start, col, triangle[part])
    return pixel.size


def _exclusive_or(scene, selection, pixel, tag, n_pixels) -> np.ndarray:
    """Which fragments of exclusive-or quads to keep: those of a pixel that only
    one of the quad's two triangles covers (and, with culling, front-facing)."""
    triangle = scene.parent[selection[tag]]
    _, inverse, count = np.unique((triangle >> 1) * n_pixels + pixel, return_inverse=True, return_counts=True)
    keep = count[inverse] == 1
    if scene.cull_backfaces:
        keep &= scene.orientation[triangle] > 0
    return keep


def _shade(frame, scene, row, col, triangle):
    """Depth and attributes of the winning fragments at pixels (row, col), (N,) each."""
    width = scene.width
    flat = row * width + col
    col, row = col.astype(np.float64), row.astype(np.float64)  # once, not in every plane's product
    depth = evaluate(np.take(scene.depth_planes, triangle, axis=1), col, row)
    np.clip(depth, -1.0, 1.0, out=depth)
    if scene.first_quad:  # a later batch: only where it is nearer than the batches before
        nearer = np.flatnonzero(depth < frame.depth.reshape(-1)[flat])
        flat, col, row, triangle, depth = flat[nearer], col[nearer], row[nearer], triangle[nearer], depth[nearer]
    quad = triangle >> 1
    frame.face.reshape(-1)[flat] = quad + scene.first_quad
    frame.depth.reshape(-1)[flat] = depth
    # One channel at a time: scattering rows of K values is several times slower than K scatters.
    channels = frame.attrs.reshape(scene.height * width, frame.attrs.shape[2]).T
    method = scene.method_of_quad[quad] if len(scene.names) > 1 else None
    for code, name in enumerate(scene.names):
        m = np.flatnonzero(method == code) if method is not None else None
        if m is None or m.size == flat.size:  # one method for all: no subsets to gather
            pixels, values = flat, _attributes(scene, name, triangle, quad, col, row)
        elif m.size:
            pixels, values = flat[m], _attributes(scene, name, triangle[m], quad[m], col[m], row[m])
        else:
            continue
        for channel, value in zip(channels, values):
            channel[pixels] = value


def _attributes(scene, name, triangle, quad, col, row) -> np.ndarray:
    """Attributes (K, N) of pixels (col, row) drawn by ``name`` in split triangle ``triangle``
    of ``quad``, (N,) each.

    Split and projective quads take their attributes from their triangle's
    planes (``_Scene.attribute_planes``): rho a / w over rho / w. The others weight their
    quad's corner attributes with their method's corner weights.
    """
    channels = scene.attrs.shape[1]
    if name in PLANE_METHODS:
        v = evaluate(np.take(scene.attribute_planes, triangle, axis=2), col, row)
        return v[:channels] / v[channels]
    px = (col + 0.5) * (2.0 / scene.width) - 1.0
    py = 1.0 - (row + 0.5) * (2.0 / scene.height)
    weights = WEIGHTS[name](np.take(scene.corners, quad, axis=2), px, py)
    corner_attrs = np.take(scene.attrs, quad, axis=2)  # (4, K, N)
    return sum(weights[i] * corner_attrs[i] for i in range(4))


def _checked_input(clip, attrs, width, height, method):
    """Validate the arguments; return clip (Q, 4, 4), attrs (Q, 4, K) float64,
    the method index of every quad (Q,) and the method names it indexes."""
    clip = np.asarray(clip, dtype=np.float64)
    attrs = np.asarray(attrs, dtype=np.float64)
    if clip.ndim != 3 or clip.shape[1:] != (4, 4):
        raise ValueError(f"clip must have shape (Q, 4, 4), got {clip.shape}")
    if attrs.ndim != 3 or attrs.shape[:2] != clip.shape[:2]:
        raise ValueError(f"attrs must have shape ({clip.shape[0]}, 4, K), got {attrs.shape}")
    for name, size in (("width", width), ("height", height)):
        if not isinstance(size, (int, np.integer)) or not 1 <= size <= MAX_SIZE:
            raise ValueError(f"{name} must be an integer from 1 to {MAX_SIZE}, got {size!r}")
    if not np.isfinite(clip).all():
        raise ValueError("clip contains NaN or infinite coordinates")
    if not np.isfinite(attrs).all():
        raise ValueError("attrs contains NaN or infinite values")
    if isinstance(method, str):
        names, method_of_quad = [method], np.zeros(clip.shape[0], dtype=np.int64)
    else:
        method = np.asarray(method, dtype=str)
        if method.shape != (clip.shape[0],):
            raise ValueError(f"method must be a name or {clip.shape[0]} names, got shape {method.shape}")
        unique, method_of_quad = np.unique(method, return_inverse=True)
        names = [str(n) for n in unique]
    for name in names:
        if name not in METHODS:
            raise ValueError(f"unknown method {name!r}; known: {', '.join(METHODS)}")
    return clip, attrs, method_of_quad, names
