"""Where a fixed mesh goes and in which form: the OBJ patched in place of its replaced faces,
PLY and OFF written whole, a USD stage as an override layer over the input."""

from __future__ import annotations

import os

from ..atomic import atomic_write
from ..mesh import Mesh
from .apply import refine_mesh
from .plan import FixPlan

USD_SUFFIXES = (".usd", ".usda", ".usdc", ".usdz")


def default_output(path: str) -> str:
    """``NAME.fixed.EXT`` beside ``path``; a ``.usdz`` package gets a ``.usda`` override layer."""
    stem, extension = os.path.splitext(path)
    if extension.lower() == ".usdz":
        extension = ".usda"
    return f"{stem}.fixed{extension}"


def write_fixed(path: str, out: str, mesh: Mesh, plan: FixPlan, header: str) -> list[str]:
    """Write the fix of ``mesh`` (read from ``path``) to ``out``, whole or not at all.

    OBJ: the input's bytes, replaced face lines dropped, new statements appended
    (:mod:`affinity.fix.objpatch`). PLY, OFF: the fixed mesh as ASCII (:mod:`affinity.fix.whole`).
    USD: a layer that sublayers ``path`` and overrides only the fixed prims (:mod:`affinity.fix.usdlayer`).
    ``header`` is the comment naming what was done. Returns notes for the user (USD: the meshes whose
    subdivided surface the fix changes). Raises OSError when ``out`` cannot be written.
    """
    extension = os.path.splitext(path)[1].lower()
    refined = refine_mesh(mesh, plan)
    if extension in USD_SUFFIXES:
        from .usdlayer import write_override_layer

        return write_override_layer(path, out, mesh, refined, header)
    if extension == ".obj":
        from .objpatch import patched_obj

        with open(path, "rb") as source:
            data = patched_obj(source.read(), mesh, refined, header)
        with atomic_write(out, binary=True) as f:
            f.write(data)
        return []
    from .whole import off_text, ply_text

    text = (ply_text if extension == ".ply" else off_text)(refined.mesh, header)
    with atomic_write(out) as f:
        f.write(text)
    return []
