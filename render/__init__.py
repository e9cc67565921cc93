"""A NumPy quad rasterizer: clip-space quads in, images out.

Knows nothing of meshes or files. See ``rasterize_quads``.
"""
