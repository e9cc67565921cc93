"""The catalogue of stiff cases: named point sets in named quads, where the formulas break.

Every case is a quad (4, 2), optional homogeneous corner coordinates w (4,) and
points (N, 2), all float64: the inputs *are* these floats, and the references
(``reference``) are exact for them. ``catalogue()`` builds the list on call.

Groups (issue 11): corners, edges, points 1e-8 ... 1e-15 from an edge inside
and outside, near corners; near-parallelograms (defect 1e-3 ... 1e-12) and
exact ones; needles of aspect 1e3 ... 1e8, along them and around their sharp
tips; offsets 1e3 ... 1e12; scales 1e-30 ... 1e30; pole quads with a repeated
corner; concave darts; bow-ties; w spread over 1e-4 ... 1e4; corners behind
the eye; points far outside.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

#: A generic convex quad, no two edges parallel.
CONVEX = np.array([[0.1, 0.2], [2.3, 0.1], [2.0, 1.7], [0.3, 1.4]])
#: Generic interior points of ``CONVEX``.
CONVEX_INSIDE = np.array([[1.2, 0.9], [0.4, 0.5], [1.9, 0.4], [1.8, 1.5], [0.5, 1.2]])
#: Dyadic corners: points at dyadic fractions of its edges lie exactly on them.
DYADIC = np.array([[0.0, 0.0], [2.0, 1.0], [1.5, 2.5], [-0.5, 1.5]])
PARALLELOGRAM = np.array([[0.0, 0.0], [3.0, 0.5], [4.0, 2.5], [1.0, 2.0]])
PARALLELOGRAM_INSIDE = np.array([[2.0, 1.25], [0.6, 0.4], [3.5, 2.1], [1.3, 1.9], [2.9, 0.7]])
DART = np.array([[0.0, 0.0], [2.0, 0.0], [0.6, 0.5], [0.0, 2.0]])  # reflex corner 2
DART_INSIDE = np.array([[0.3, 0.3], [1.2, 0.15], [0.15, 1.2], [0.55, 0.45], [0.6, 0.5 - 1e-9]])
#: A planar quad in clip space (x, y, w) crossing the eye plane.
BEHIND_ONE = np.array([[-0.6, -0.5, 1.0], [0.7, -0.4, 1.2], [0.4, 0.9, -0.5], [-0.5, 0.6, 0.9]])
BEHIND_TWO = np.array([[-0.6, -0.5, 1.0], [0.7, -0.4, 1.2], [0.4, 0.9, -0.5], [-0.5, 0.6, -0.3]])


@dataclass(frozen=True)
class Case:
    """One catalogue entry.

    Attributes
    ----------
    name, group : str
    points : (N, 2) float64 or float32
    quad : (4, 2) float64 or float32
    w : (4,) float or None
        Homogeneous corner coordinates for the perspective mean value
        coordinates (eq. 10, 11); ``inverse_bilinear`` ignores them.
    far : bool
        Points far outside: errors and the condition are relative to the
        largest component of the result (infinity norm).
    bilinear : bool
        Whether every point has a unique inverse bilinear solution (see
        ``reference.inverse_bilinear_exact``), so the case runs for it.
    """

    name: str
    group: str
    points: np.ndarray
    quad: np.ndarray
    w: np.ndarray | None = None
    far: bool = False
    bilinear: bool = True

    def rounded(self, dtype) -> Case:
        """The same case with every input rounded to ``dtype`` (e.g. float32)."""
        return replace(
            self,
            points=self.points.astype(dtype),
            quad=self.quad.astype(dtype),
            w=None if self.w is None else self.w.astype(dtype),
        )


def catalogue() -> list[Case]:
    """All cases, in groups (names are unique and stable: they key the committed table)."""
    return [
        *_corners_and_edges(),
        *_near_edges(),
        *_near_corners(),
        *_parallelograms(),
        *_needles(),
        *_offsets_and_scales(),
        *_poles(),
        *_darts_and_bowties(),
        *_perspective(),
        *_far_outside(),
    ]


def _case(name, group, points, quad, w=None, **flags) -> Case:
    return Case(
        name, group, np.asarray(points, dtype=np.float64).reshape(-1, 2), np.asarray(quad, dtype=np.float64),
        None if w is None else np.asarray(w, dtype=np.float64), **flags,
    )


def _edge_points(quad, fractions, distance):
    """Points at ``fractions`` along every edge, ``distance`` off it (outward > 0), rounded to float64.

    Returns (4 * F, 2): edge-major.
    """
    a, b = quad, np.roll(quad, -1, axis=0)
    edge = b - a
    outward = np.stack([edge[:, 1], -edge[:, 0]], axis=1) / np.linalg.norm(edge, axis=1)[:, None]
    if _signed_area(quad) < 0:
        outward = -outward
    f = np.asarray(fractions)[None, :, None]
    return (a[:, None] + f * edge[:, None] + distance * outward[:, None]).reshape(-1, 2)


def _signed_area(quad):
    x, y = quad[:, 0], quad[:, 1]
    return 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)


def _corners_and_edges():
    """A generic case (the naive forms must pass it), corners, points exactly on edges."""
    return [
        _case("inside", "generic", CONVEX_INSIDE, CONVEX),
        _case("corners", "corners", CONVEX, CONVEX),
        _case("corners-dart", "corners", DART, DART, bilinear=False),  # the patch folds: q2 has two (s, t)
        _case("edges-exact", "edges", _edge_points(DYADIC, [0.25, 0.5, 0.8125], 0.0), DYADIC),
        _case("edges-rounded", "edges", _edge_points(CONVEX, [0.1, 0.3, 0.7], 0.0), CONVEX),
    ]


def _near_edges():
    cases = []
    for exponent in (8, 10, 12, 15):
        for side, sign in (("inside", -1.0), ("outside", 1.0)):
            points = _edge_points(CONVEX, [0.3, 0.6], sign * 10.0**-exponent)
            cases.append(_case(f"edge-{side}-1e-{exponent}", "near edges", points, CONVEX))
    return cases


def _near_corners():
    centre = CONVEX.mean(axis=0)
    inward = (centre - CONVEX) / np.linalg.norm(centre - CONVEX, axis=1)[:, None]
    along = (np.roll(CONVEX, -1, axis=0) - CONVEX) / 2
    cases = []
    for exponent in (8, 12, 15):
        d = 10.0**-exponent
        points = np.concatenate([CONVEX + d * inward, CONVEX - d * inward, CONVEX + d * along])
        cases.append(_case(f"corner-near-1e-{exponent}", "near corners", points, CONVEX))
    return cases


def _parallelograms():
    rectangle = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 1.0], [0.0, 1.0]])
    cases = [
        _case("parallelogram-rectangle", "parallelograms", [[1.5, 0.5], [0.3, 0.9], [2.7, 0.1], [1.0, 2.0]], rectangle),
        _case("parallelogram-exact", "parallelograms", PARALLELOGRAM_INSIDE, PARALLELOGRAM),
    ]
    for exponent in (3, 6, 9, 12):
        quad = PARALLELOGRAM.copy()
        quad[2, 1] += 10.0**-exponent
        cases.append(_case(f"parallelogram-defect-1e-{exponent}", "parallelograms", PARALLELOGRAM_INSIDE, quad))
    return cases


def _needles():
    cases = []
    fractions = np.array([[0.3, 0.5], [0.5, 0.2], [0.9, 0.7], [0.02, 0.5], [0.999, 0.4]])
    for exponent in (3, 5, 8):
        h = 10.0**-exponent
        quad = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.6 * h], [0.0, h]])  # a thin trapezoid
        width = h * (1 - 0.4 * fractions[:, 0])
        points = np.stack([fractions[:, 0], fractions[:, 1] * width], axis=1)
        cases.append(_case(f"needle-1e{exponent}", "needles", points, quad))
    # A tilted needle: rounding the long offsets moves corners across it, so its
    # condition grows with the aspect; 1e4 keeps it near 1e-12.
    angle = 0.5
    rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    h = 1e-4
    quad = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.6 * h], [0.0, h]]) @ rotation.T
    points = np.stack([fractions[:, 0], fractions[:, 1] * h * (1 - 0.4 * fractions[:, 0])], axis=1) @ rotation.T
    cases.append(_case("needle-tilted-1e4", "needles", points, quad))
    # Around the sharp tip q1 of a kite-shaped needle, inside and out: p sees
    # q0 and q2 in almost the same direction, so tan(alpha_0 / 2) and
    # tan(alpha_1 / 2) nearly cancel in mu_1.
    directions = np.array([[np.cos(a), np.sin(a)] for a in (0.0, 1.5, 2.5, np.pi)])
    for exponent in (4, 8):
        h = 10.0**-exponent
        quad = np.array([[0.0, 0.0], [1.0, 0.4 * h], [0.0, h], [-0.5, 0.5 * h]])
        points = (quad[1] + np.array([10.0**-e for e in (6, 9, 12, 15)])[:, None, None] * directions).reshape(-1, 2)
        cases.append(_case(f"needle-tip-1e{exponent}", "needles", points, quad))
    # A folded sliver, 6.5e4 long and 3e-4 high, away from the origin: the two
    # rows of P(s, t) = p differ by 1e8 in size, so a Newton step must be judged
    # row by row (|F| alone only sees the long row).
    sliver = np.array([[-29787.03, 54.26687], [-46562.64, 54.26699], [18014.93, 54.26703], [16121.89, 54.26719]])
    st = np.array([[0.0016587309, 0.90018641], [0.3, 0.2], [0.001, 0.1], [0.6, 0.95]])
    cases.append(_case("needle-sliver", "needles", _bilinear_points(sliver, st), sliver))
    return cases


def _bilinear_points(quad, st):
    """P(s, t) (N, 2) of the patch through quad (4, 2) at parameters st (N, 2)."""
    s, t = st[:, :1], st[:, 1:]
    return (1 - s) * (1 - t) * quad[0] + s * (1 - t) * quad[1] + s * t * quad[2] + (1 - s) * t * quad[3]


def _offsets_and_scales():
    cases = []
    for exponent in (3, 6, 9, 12):
        offset = np.array([10.0**exponent, -0.7 * 10.0**exponent])
        cases.append(_case(f"offset-1e{exponent}", "offsets", CONVEX_INSIDE + offset, CONVEX + offset))
    for exponent in (-30, -9, -4, 4, 9, 30):
        scale = 10.0**exponent
        cases.append(_case(f"scale-1e{exponent:+d}", "scales", CONVEX_INSIDE * scale, CONVEX * scale))
    return cases


def _poles():
    triangle = np.array([[0.0, 0.0], [2.0, 0.2], [0.9, 1.7], [0.9, 1.7]])  # repeated last corner
    apex, base = triangle[2], (triangle[0] + triangle[1]) / 2
    toward = (base - apex) / np.linalg.norm(base - apex)
    side = (triangle[1] - apex) / np.linalg.norm(triangle[1] - apex)
    near_apex = [apex + 10.0**-e * (toward if e % 2 else side + toward) for e in (4, 6, 8, 10, 12)]
    collapsed_first = np.array([[1.0, 0.0], [1.0, 0.0], [2.1, 1.6], [-0.1, 1.5]])  # repeated corner 0 = 1
    return [
        _case("pole-inside", "poles", [[0.9, 0.6], [0.3, 0.1], [1.7, 0.3], [0.95, 1.5]], triangle),
        _case("pole-near-apex", "poles", near_apex, triangle),
        _case("pole-first-edge", "poles", [[1.0, 0.7], [1.0, 1e-6], [1.0 + 1e-9, 1e-8], [0.2, 1.3], [1.9, 1.4]],
              collapsed_first),
    ]


def _darts_and_bowties():
    dart_1 = np.roll(DART, -1, axis=0)  # reflex corner 1
    bowtie = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    skew = np.array([[0.0, 0.0], [2.0, 1.5], [2.0, 0.0], [0.0, 1.0]])
    lobes = [[0.15, 0.5], [0.85, 0.5], [0.3, 0.45], [0.7, 0.55], [0.05, 0.9]]
    return [
        _case("dart-reflex-2", "darts", DART_INSIDE, DART),
        _case("dart-reflex-1", "darts", DART_INSIDE, dart_1),
        _case("bowtie", "bow-ties", lobes, bowtie),
        _case("bowtie-skew", "bow-ties", [[0.3, 0.4], [1.7, 0.6], [1.2, 0.5], [0.1, 0.2]], skew),
    ]


def _projected(clip, weights):
    """Screen corners (4, 2), w (4,) and the screen points (N, 2) of the clip-space
    combinations ``weights`` (N, 4) of the corners (x, y, w) (4, 3)."""
    combined = np.asarray(weights) @ clip
    return clip[:, :2] / clip[:, 2:], clip[:, 2], combined[:, :2] / combined[:, 2:]


def _perspective():
    cases = []
    for name, w in (("w-1e-4", [1e-4, 1.0, 1.0, 1.0]), ("w-1e4", [1.0, 1e4, 1.0, 1.0]),
                    ("w-spread", [1e-4, 1e4, 1e-4, 1e4])):
        cases.append(_case(name, "perspective", CONVEX_INSIDE, CONVEX, w, bilinear=False))
    # Points of the quad's visible part: combinations of the corners with w > 0.
    weights = [[0.5, 0.3, 0.0, 0.2], [0.2, 0.5, 0.05, 0.25], [0.25, 0.25, 0.1, 0.4], [0.6, 0.1, 0.02, 0.28]]
    for name, clip in (("behind-eye-one", BEHIND_ONE), ("behind-eye-two", BEHIND_TWO)):
        quad, w, points = _projected(clip, weights)
        assert (np.asarray(weights) @ clip[:, 2] > 0).all()
        cases.append(_case(name, "perspective", points, quad, w, bilinear=False))
    return cases


def _far_outside():
    directions = np.array([[1.0, 0.3], [-0.4, 1.0], [-1.0, -0.8], [0.5, -1.0]])
    return [
        _case(f"far-1e{e}", "far outside", CONVEX.mean(axis=0) + 10.0**e * directions, CONVEX, far=True)
        for e in (2, 4, 6)
    ]
