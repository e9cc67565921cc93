"""Eye rays against bilinear patches: the parameters (s, t) of the ``exact`` method.

A quad with 3-D corners P_i is the bilinear patch

    P(s, t) = (1-s)(1-t) P_0 + s(1-t) P_1 + s t P_2 + (1-s) t P_3,

the surface a modelling tool means by a (possibly nonplanar) quad. The camera
takes world points to clip space by one linear map of homogeneous coordinates,
and the bilinear weights sum to 1, so the clip-space image of P(s, t) is the
same combination of the clip-space corners H_i = (X_i, Y_i, Z_i, W_i), with
the same (s, t). Intersecting in clip space therefore *is* the 3-D ray /
patch intersection, without world corners or an inverse camera, and it holds
for corners behind the eye (W < 0) too.

The eye ray through the pixel centre p = (px, py) (NDC) is the set of points
with X = px W and Y = py W: two planes through the eye, whose values at the
corners are h_i = (X_i - px W_i, Y_i - py W_i), and W > 0 picks the half in
front of the eye. A patch point lies on the ray when

    a + s b + t c + s t d = 0,   a = h_0, b = h_1 - h_0, c = h_3 - h_0,
                                 d = h_0 - h_1 + h_2 - h_3

(two equations, the components of the 2-vectors). Eliminating s gives
k2 t^2 + k1 t + k0 = 0 with k2 = c x d, k1 = a x d + c x b, k0 = a x b, solved
without cancellation (Q = -(k1 + sign(k1) sqrt(k1^2 - 4 k2 k0)) / 2, t = k0 / Q
and t = Q / k2; for a parallelogram, k2 = 0 and only the first is finite).
Each root gets its s from t by least squares and two safeguarded Newton
steps on the 2-D system (``render.coords``); a root counts only if it then
solves the system (elimination adds the spurious t = 1 at a collapsed edge).
A line can meet a nonplanar patch twice; the hit kept is the one inside the
unit square, in front of the eye (W(s, t) > 0) and nearest (smallest NDC depth
Z / W). Inside a quad's screen outline, with every corner in front of the
eye, there is exactly one (the projection of the patch has degree one there),
so the choice matters for quads crossing the eye plane.
"""

from __future__ import annotations

import numpy as np

from render.coords import NEWTON_STEPS, bilinear_weights, cross2, newton_step, s_given_t

#: (s, t) this far outside the unit square still count as on the patch: pixel
#: centres on a quad's edge come out a few ulps outside by rounding.
SQUARE_TOLERANCE = 1e-9
#: A candidate is on the ray when the residual |a + s b + t c + s t d| of the
#: scaled system (coefficients at most 1) is below this. It rejects the
#: complex pair's real part (the ray misses the patch's surface) and the
#: spurious root t = 1 that eliminating s brings in at a collapsed edge
#: (q2 = q3, a triangle passed as a quad), where dP/ds = 0 for every point.
RESIDUAL_TOLERANCE = 1e-9


def ray_patch_parameters(corners, px, py):
    """Patch parameters of the nearest hit of each pixel's eye ray.

    Parameters
    ----------
    corners : (4, 4, N) float64
        Clip-space corners (component x, y, z, w; corner; pixel) of the quad
        each pixel is in.
    px, py : (N,) float64
        The pixel centres in NDC.

    Returns
    -------
    s, t : (N,) float64
        In [0, 1]. Where the ray misses the patch (see ``hit``) the candidate
        nearest the unit square, clamped into it: the attribute then stays
        within the corners' bilinear range.
    hit : (N,) bool
        The ray meets the patch in front of the eye. It does for every pixel
        centre inside the screen outline of a quad whose corners are all in
        front of the eye (the patch's projection covers its outline). Misses
        are pixel centres that the rasterizer's fixed-point coverage admits a
        hair outside the outline (snapping moves edges by up to 1/512 pixel;
        clamping puts them on the edge), and pixels of quads with a corner at
        W <= 0, whose covered pixels come from the clipped split triangles,
        which the patch need not cover.

    Examples
    --------
    A unit square two units in front of the eye (w = distance), seen head on:

    >>> square = np.array([[-1, 1, 1, -1], [-1, -1, 1, 1], [0, 0, 0, 0], [2, 2, 2, 2]], float)
    >>> s, t, hit = ray_patch_parameters(square[..., None], np.array([0.25]), np.array([0.0]))
    >>> float(s[0]), float(t[0]), bool(hit[0])
    (0.75, 0.5, True)
    """
    X, Y, Z, W = corners
    h = np.stack([X - px * W, Y - py * W], axis=1)  # (4, 2, N): h_i per component
    a, b, c = h[0], h[1] - h[0], h[3] - h[0]
    d = (h[2] - h[3]) - b
    scale = np.abs(h).max(axis=(0, 1))  # the system is homogeneous: scale it to O(1)
    scale[scale == 0] = 1.0
    a, b, c, d = (v / scale for v in (a, b, c, d))
    k2 = cross2(c, d)
    k1 = cross2(a, d) + cross2(c, b)
    k0 = cross2(a, b)
    Q = -0.5 * (k1 + np.copysign(np.sqrt(np.maximum(k1 * k1 - 4.0 * k2 * k0, 0.0)), k1))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        t = np.stack([k0 / Q, Q / k2])  # (2, N): both roots
        s = s_given_t(a, b, c, d, t)
        s = np.where(np.isnan(s) & np.isfinite(t), 0.5, s)  # a collapsed edge: every s is the same point
        finite = np.isfinite(s) & np.isfinite(t)
        s, t = np.where(finite, s, 0.5), np.where(finite, t, 0.5)
        for _ in range(NEWTON_STEPS):
            s, t = newton_step(a, b, c, d, s, t)
        weights = bilinear_weights(s, t)  # (4, 2, N)
        w_hit = np.einsum("kmn,kn->mn", weights, W)
        z_hit = np.einsum("kmn,kn->mn", weights, Z)
        residual = np.hypot(*(a[:, None] + s[None] * b[:, None] + t[None] * (c[:, None] + s[None] * d[:, None])))
    outside = np.maximum(np.maximum(-s, s - 1.0), np.maximum(-t, t - 1.0))
    outside = np.where(finite & (w_hit > 0), outside, np.inf)
    on_ray = residual <= RESIDUAL_TOLERANCE
    on_patch = (outside <= SQUARE_TOLERANCE) & on_ray
    # The second root wins when only it is on the patch, or both are and it is
    # nearer (z / w smaller, both w > 0), or neither is and it is on the ray
    # (or not, like the first) and nearer the square.
    nearer = z_hit[1] * w_hit[0] < z_hit[0] * w_hit[1]
    closer = (on_ray[1] & ~on_ray[0]) | ((on_ray[1] == on_ray[0]) & (outside[1] < outside[0]))
    second = np.where(on_patch[0], on_patch[1] & nearer, on_patch[1] | closer)
    pick = second.astype(np.intp)[None]
    s = np.take_along_axis(s, pick, axis=0)[0]
    t = np.take_along_axis(t, pick, axis=0)[0]
    hit = np.take_along_axis(on_patch, pick, axis=0)[0]
    return np.clip(s, 0.0, 1.0), np.clip(t, 0.0, 1.0), hit

