"""quad-affinity: lint quad meshes for attribute affinity and render them with a hybrid rasterizer.

Importing this package is cheap (NumPy is not even imported): ``render_mesh`` and
``RenderOptions`` are looked up in :mod:`affinity.draw` on first use, and the
renderer, Pillow, Jinja2, matplotlib, trimesh, libigl and pyvista are imported
where they are used.
"""

__version__ = "0.1.0"

#: Names exported lazily: name -> the module that defines it.
_LAZY = {"render_mesh": "affinity.draw", "RenderOptions": "affinity.draw", "RenderResult": "affinity.draw"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'affinity' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_LAZY])


__all__ = ["RenderOptions", "RenderResult", "__version__", "render_mesh"]
