"""quad-affinity: lint quad meshes for attribute affinity and render them with a hybrid rasterizer.

Importing this package is cheap (NumPy only); the renderer, Pillow, Jinja2,
matplotlib, trimesh, libigl and pyvista are imported where they are used.
"""

__version__ = "0.1.0"
