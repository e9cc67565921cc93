"""A mesh and a view in, an image out: framing, the renderer's quads, routing, shading, textures, PNG.

- :mod:`.drawing`: ``render_mesh(mesh, RenderOptions) -> RenderResult``, the one entry point;
- :mod:`.framing`: cameras and up axes when the user names none;
- :mod:`.quads`: the mesh as the renderer's quads (triangles and n-gons fanned);
- :mod:`.routing`: the hybrid's per-quad choice between ``split`` and ``mvc``;
- :mod:`.shading`: per-corner inputs, pixel colours, the shared palette;
- :mod:`.texture`, :mod:`.png`: images in and out;
- :mod:`.view`: the 3-D view of ``affinity view`` and the report's overview (pyvista, the ``view`` extra).

``render`` (the rasterizer) knows nothing of meshes; this package is where meshes
meet it. Heavy imports (``render``, Pillow) happen inside the functions.
"""

from .drawing import RenderOptions, RenderResult, render_mesh

__all__ = ["RenderOptions", "RenderResult", "render_mesh"]
