"""Q106: what subdivision does to the texture by itself (design.md, "Subdivision")."""

from __future__ import annotations

import threading

import numpy as np

from .families import UV_LAYOUT
from .registry import Measured, rule

#: One computation of a mesh's drift for all the batches of a lint pass (they run on threads).
_LOCK = threading.Lock()


def _drift_of(quads) -> np.ndarray | None:
    """(F, 2) uv units: the mesh's UV drift (:func:`affinity.subdivision.drift.mesh_uv_drift`), computed once a
    pass and kept with the pass's corner tables; None where the settings draw the whole mesh as its cage."""
    from ..subdivision.drift import mesh_uv_drift
    from ..subdivision.pieces import drawn_levels

    tables = quads.tables
    with _LOCK:
        if not hasattr(tables, "uv_drift"):
            drawn = any(level != 0 for level in drawn_levels(quads.mesh, quads.settings)[2])
            tables.uv_drift = mesh_uv_drift(quads.mesh, quads.settings) if drawn else None
    return tables.uv_drift


@rule(code="Q106", name="uv-drift", unit="texels", default_threshold=1.0, visible_threshold=4.0,
      attribute="texcoords", family=UV_LAYOUT, example_flags=("--subdivision", "limit"))
def uv_drift(quads) -> Measured:
    """Subdivision moves the texture.

    What it does:
        On a mesh drawn subdivided (the ``subdivision`` setting and ``profile``: USD meshes by their own
        subdivisionScheme and faceVaryingLinearInterpolation, OBJ, PLY and OFF by ``fvar-interpolation``
        with ``--subdivision level:N`` or ``limit``), measures the largest distance over each quad between
        the limit surface's texture coordinates and the cage's bilinear ones, in texels (sampled at the
        corners of the quad refined twice, a 5 x 5 grid). In the example the shared edge's u = 0.2
        moves to (0 + 4 x 0.2 + 1) / 6 = 0.3 at the limit (the smooth boundary rule): 0.1 x 1024 = 102.4
        texels.

    Why it matters:
        Under the smooth face-varying rules (every rule but ``all``) the uv is subdivided like the positions:
        an island's edges are smoothed and its interior relaxed, so the texture slides over the surface even
        where every quad is a parallelogram in uv, and the bake made on the cage no longer lines up. No split
        is involved: refining the quads does not remove it.

    Example:
        # two quads whose shared edge sits at u = 0.2, not halfway
        v 0 0 0
        v 1 0 0
        v 2 0 0
        v 2 1 0
        v 1 1 0
        v 0 1 0
        vt 0 0
        vt 0.2 0
        vt 1 0
        vt 1 1
        vt 0.2 1
        vt 0 1
        f 1/1 2/2 5/5 6/6
        f 2/2 3/3 4/4 5/5

    Prints:
        example.obj:14:1: Q106 error uv-drift: subdivision moves the texture: no texture found, texels of an assumed 1024x1024 texture (give the size with --texture-size or the texture-size setting) (102.4 vs 1 texels) [face 0]
        example.obj:15:1: Q106 error uv-drift: subdivision moves the texture (102.4 vs 1 texels) [face 1]

    Use instead:
        # the shared edge halfway, where the smooth rules leave it
        v 0 0 0
        v 1 0 0
        v 2 0 0
        v 2 1 0
        v 1 1 0
        v 0 1 0
        vt 0 0
        vt 0.5 0
        vt 1 0
        vt 1 1
        vt 0.5 1
        vt 0 1
        f 1/1 2/2 5/5 6/6
        f 2/2 3/3 4/4 5/5

    References:
        OpenSubdiv, Subdivision Surfaces: face-varying interpolation rules (Sdc::Options::FVarLinearInterpolation);
        UsdGeomMesh, faceVaryingLinearInterpolation.

    How to fix:
        Author faceVaryingLinearInterpolation = "all" on the mesh (USD; Blender: the Subdivision Surface
        modifier's UV Smooth = None), which draws the cage's uv bilinearly: the drift is 0; or space the uv
        the way the smooth rules place it (Blender's UV Smooth set to the renderer's rule before baking).
    """
    drift = _drift_of(quads)
    if drift is None:
        return Measured.nothing()
    drift = drift[quads.faces]
    rows = np.flatnonzero(np.isfinite(drift[:, 0]))
    size = quads.texel_size(rows)
    texels = drift[rows] * size
    return Measured(rows, np.hypot(texels[:, 0], texels[:, 1]))
