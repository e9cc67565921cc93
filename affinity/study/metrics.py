"""How far a render is from the exact reference: attribute error, image quality, crease.

All functions are vectorised over pixels (and over quads for the crease) and
work on the pixels that both renders cover.

- :func:`error_summary` — RMS, 99th percentile and maximum of a per-pixel error
  (``affinity.attributes.pixel_error`` gives it in the lint's units:
  texels for uv, 1/255 steps for colours).
- :func:`psnr` and :func:`ssim` — of the textured images, in [0, 1] RGB.
  SSIM is Wang, Bovik, Sheikh & Simoncelli 2004 (eq. 13, Gaussian window
  sigma 1.5, K1 = 0.01, K2 = 0.03), averaged over the channels and the mask.
- :func:`crease` — the jump of the attribute gradient across each quad's
  diagonal, fitted per quad (see there).
- :func:`texels_per_pixel` — the local texture density of a render, which turns
  an error in texels into one in screen pixels (what the hybrid's pixel
  tolerance bounds).
"""

from __future__ import annotations

import numpy as np

SSIM_SIGMA = 1.5
SSIM_RADIUS = 5  # an 11-tap window, as in the paper
SSIM_K1, SSIM_K2 = 0.01, 0.03
#: The crease is fitted on the pixels of a quad within this many times its size
#: (the square root of its pixel count) of its diagonal ...
CREASE_BAND = 0.25
#: ... and only with at least this many such pixels on each side.
CREASE_MIN_SIDE = 12


def error_summary(error: np.ndarray) -> dict[str, float]:
    """RMS, 99th percentile (linear interpolation) and maximum of errors (N,) >= 0; NaN when N = 0.

    >>> error_summary(np.array([3.0, 4.0]))
    {'rms': 3.5355339059327378, 'p99': 3.99, 'max': 4.0}
    """
    if error.size == 0:
        return {"rms": np.nan, "p99": np.nan, "max": np.nan}
    return {
        "rms": float(np.sqrt(np.mean(np.square(error)))),
        "p99": float(np.percentile(error, 99)),
        "max": float(error.max()),
    }


def psnr(image: np.ndarray, reference: np.ndarray, mask: np.ndarray, peak: float = 1.0) -> float:
    """Peak signal-to-noise ratio in dB of images (H, W, C) on mask (H, W); inf when equal there.

    10 log10(peak^2 / MSE), the mean square error over the mask's pixels and all channels.
    """
    mse = float(np.mean(np.square(image[mask].astype(np.float64) - reference[mask])))
    return np.inf if mse == 0 else 10.0 * np.log10(peak * peak / mse)


def ssim(image: np.ndarray, reference: np.ndarray, mask: np.ndarray, data_range: float = 1.0) -> float:
    """Mean structural similarity of images (H, W, C) over mask (H, W) and channels (1 = identical).

    Local means, variances and covariance are Gaussian-weighted (sigma 1.5,
    11 taps, image borders reflected); the SSIM map is evaluated on the whole
    image and averaged where ``mask`` is set.
    """
    x = np.moveaxis(np.asarray(image, dtype=np.float64), -1, 0)
    y = np.moveaxis(np.asarray(reference, dtype=np.float64), -1, 0)
    c1, c2 = (SSIM_K1 * data_range) ** 2, (SSIM_K2 * data_range) ** 2
    mu_x, mu_y = _gaussian_blur(x), _gaussian_blur(y)
    var_x = _gaussian_blur(x * x) - mu_x * mu_x
    var_y = _gaussian_blur(y * y) - mu_y * mu_y
    cov = _gaussian_blur(x * y) - mu_x * mu_y
    index = ((2 * mu_x * mu_y + c1) * (2 * cov + c2)) / ((mu_x**2 + mu_y**2 + c1) * (var_x + var_y + c2))
    return float(index[:, mask].mean())


def _gaussian_blur(channels: np.ndarray) -> np.ndarray:
    """Separable Gaussian filter (sigma ``SSIM_SIGMA``, normalised taps) of (C, H, W), borders reflected."""
    offsets = np.arange(-SSIM_RADIUS, SSIM_RADIUS + 1)
    taps = np.exp(-0.5 * (offsets / SSIM_SIGMA) ** 2)
    taps /= taps.sum()
    for axis in (1, 2):
        pad = [(0, 0)] * 3
        pad[axis] = (SSIM_RADIUS, SSIM_RADIUS)
        windows = np.lib.stride_tricks.sliding_window_view(np.pad(channels, pad, mode="reflect"), taps.size, axis)
        channels = windows @ taps
    return channels


def texels_per_pixel(uv: np.ndarray, face: np.ndarray, texture_size) -> np.ndarray:
    """Local texture density sqrt|det d(u W, v H) / d(column, row)| of a render, (H, W) float64.

    The on-screen scale the hybrid's routing uses per quad (``affinity.draw.routing``:
    sqrt(screen area / uv area)), here per pixel, from differences between
    neighbouring pixels of the same quad (forward where the next pixel belongs
    to it, else backward); NaN where a pixel has no such neighbour in a direction.

    Parameters
    ----------
    uv : (H, W, 2) float64, texture coordinates of a render
    face : (H, W) int64, the quad at each pixel (-1 empty)
    texture_size : int or (width, height) in texels
    """
    texels = uv * np.broadcast_to(np.asarray(texture_size, dtype=np.float64), (2,))
    along_row = _same_quad_difference(texels, face, axis=1)  # d/d column, (H, W, 2)
    down = _same_quad_difference(texels, face, axis=0)  # d/d row
    return np.sqrt(np.abs(along_row[..., 0] * down[..., 1] - along_row[..., 1] * down[..., 0]))


def _same_quad_difference(values: np.ndarray, face: np.ndarray, axis: int) -> np.ndarray:
    """Difference of values (H, W, C) to the next pixel along ``axis`` of the same quad, else to the previous one."""
    size = face.shape[axis]
    index = np.arange(size)
    shape = [1, 1]
    shape[axis] = size
    last, first = (index == size - 1).reshape(shape), (index == 0).reshape(shape)
    covered = face >= 0
    forward_ok = covered & (np.roll(face, -1, axis) == face) & ~last
    backward_ok = covered & (np.roll(face, 1, axis) == face) & ~first
    forward = np.roll(values, -1, axis) - values
    backward = values - np.roll(values, 1, axis)
    return np.where(forward_ok[..., None], forward, np.where(backward_ok[..., None], backward, np.nan))


def crease(values: np.ndarray, face: np.ndarray, clip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Jump of the attribute gradient across each quad's 0-2 diagonal, in attribute units per pixel.

    Across a line, a continuous field whose gradient jumps has the form
    smooth + J max(0, d), d the signed distance (pixels) to the line: the jump
    of the gradient is J times the line's unit normal. Per quad, the pixels it
    covers within ``CREASE_BAND`` times its size of the screen diagonal
    through corners 0 and 2 are fitted by least squares with a quadratic in
    the pixel position (absorbing the smooth part near the diagonal: the
    curvature of mvc, bilinear, perspective) plus the hinge J max(0, d); J is
    the crease. For the two-triangle split, whose field is smooth on each side
    of that diagonal and continuous across it, J is its gradient jump; a field
    smooth across the diagonal gives J = 0 up to what the quadratic cannot
    absorb. Pass the corners renumbered (1, 2, 3, 0) for the diagonal 1-3.

    Parameters
    ----------
    values : (H, W, K) float64, the attributes of a render
    face : (H, W) int64, the quad at each pixel (-1 empty)
    clip : (Q, 4, 4) float64, the quads' clip-space corners

    Returns
    -------
    jump : (Q, K) float64, J per quad; NaN for quads seen with fewer than
        ``CREASE_MIN_SIDE`` pixels on a side of the diagonal within the band,
        or with corner 0 or 2 at or behind the eye
    pixels : (Q,) int64, the pixels each quad covers
    """
    height, width = face.shape
    n_quads = clip.shape[0]
    rows, cols = np.nonzero(face >= 0)
    quad = face[rows, cols]
    pixels = np.bincount(quad, minlength=n_quads)
    size = np.sqrt(np.maximum(pixels, 1))  # pixels per unit of the local coordinates
    with np.errstate(divide="ignore", invalid="ignore"):
        w = clip[:, (0, 2), 3]
        ends = np.stack([(clip[:, (0, 2), 0] / w + 1) * (0.5 * width) - 0.5,
                         (1 - clip[:, (0, 2), 1] / w) * (0.5 * height) - 0.5], axis=-1)  # (Q, 2, 2): col, row
        along = ends[:, 1] - ends[:, 0]
        normal = np.stack([-along[:, 1], along[:, 0]], axis=-1) / np.linalg.norm(along, axis=-1, keepdims=True)
        distance = (cols - ends[quad, 0, 0]) * normal[quad, 0] + (rows - ends[quad, 0, 1]) * normal[quad, 1]
    seen = (w > 0).all(axis=1) & np.isfinite(normal).all(axis=1)
    near = np.abs(np.nan_to_num(distance, nan=np.inf)) <= CREASE_BAND * size[quad]
    rows, cols, quad, distance = rows[near], cols[near], quad[near], distance[near]
    f = values[rows, cols]  # (P, K)
    count = np.maximum(np.bincount(quad, minlength=n_quads), 1)
    x = (cols - (np.bincount(quad, cols, n_quads) / count)[quad]) / size[quad]
    y = (rows - (np.bincount(quad, rows, n_quads) / count)[quad]) / size[quad]
    beyond = distance > 0
    design = np.stack([np.ones_like(x), x, y, x * x, x * y, y * y, np.where(beyond, distance, 0.0) / size[quad]], 1)
    m = design.shape[1]
    normal_matrix = np.empty((n_quads, m, m))
    for i in range(m):  # m (m + 1) / 2 bincounts, each over all pixels: no loop per quad or pixel
        for j in range(i, m):
            normal_matrix[:, i, j] = normal_matrix[:, j, i] = np.bincount(quad, design[:, i] * design[:, j], n_quads)
    rhs = np.stack([np.stack([np.bincount(quad, design[:, i] * f[:, k], n_quads) for k in range(f.shape[1])], -1)
                    for i in range(m)], 1)  # (Q, m, K)
    on_far_side = np.bincount(quad, beyond, n_quads)
    fitted = seen & (on_far_side >= CREASE_MIN_SIDE) & (count - on_far_side >= CREASE_MIN_SIDE)
    jump = np.full((n_quads, f.shape[1]), np.nan)
    if fitted.any():
        coefficients = np.linalg.pinv(normal_matrix[fitted], rcond=1e-12, hermitian=True) @ rhs[fitted]
        jump[fitted] = coefficients[:, -1] / size[fitted, None]
    return jump, pixels
