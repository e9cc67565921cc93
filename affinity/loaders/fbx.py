"""FBX files (``.fbx``, binary and ASCII) through ufbx, the ``fbx`` extra.

``ufbx`` is imported when an FBX file is read: without the extra, such a file
gets one line naming the install command and the other files are still checked.
The file is read in a forked child process (:mod:`affinity.loaders.isolated`), so
a crash of the native reader on a hostile file is one Q901 line for that file.

A file loads as one :class:`~affinity.mesh.Mesh` that concatenates every visible
mesh node in the scene's node order (:mod:`affinity.loaders.fbxscene`):

- polygons as authored (triangles, quads and n-gons, corner order kept);
- positions in world space through each node's transform (geometric transform
  included), in the file's own units and axes: nothing is converted. The scene's
  up axis and unit are recorded (``Mesh.up_axis``, ``Mesh.meters_per_unit``) for the view;
- per-corner uv from the first uv set, or the one named by ``--uv-primvar``
  (:attr:`affinity.loaders.usd.UsdOptions.uv_primvar`), normals (world space) and
  vertex colours (RGB, clamped to [0, 1]; a vertex whose corners disagree is split,
  as in USD);
- each node is a group named by its node path (``/Root/Body/Mesh``) with
  ``prim_face_start``, so findings read ``path:/Root/Body/Mesh:face N`` as USD's
  do; nodes that instance one geometry share a source (``prim_sources``) and are
  reported once, with every node path, as USD's shared geometry is;
- materials bind textures by role (:mod:`affinity.loaders.fbxmaterials`), images
  embedded in the file read from memory.

``affinity fix`` does not write FBX (:data:`NO_FIX`).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from ..errors import MeshError

if TYPE_CHECKING:
    from ..mesh import Mesh
    from .usd import UsdOptions

INSTALL = "pip install 'quad-affinity[fbx]'"
#: Why ``affinity fix`` leaves an FBX file, and the way out.
NO_FIX = ("FBX is not written (no FBX writer exists on PyPI): export OBJ or USD from the DCC tool, "
          "fix that, and re-export")


def load_fbx(path, options: UsdOptions | None = None) -> Mesh:
    """Read the FBX file at ``path`` (see the module docstring); ``options.uv_primvar`` names the uv set.

    Raises MeshError (line 0) when ufbx is missing, the file cannot be read, the reader crashes, or a
    mesh's arrays disagree.
    """
    try:
        import ufbx  # noqa: F401 - imported here so the child process does not pay for it
    except ImportError:
        raise MeshError(path, 0, f"reading FBX needs ufbx: {INSTALL}") from None
    from .fbxscene import read_fbx
    from .imagesize import embed
    from .isolated import read_isolated

    mesh, embedded = read_isolated(os.fspath(path), read_fbx, os.fspath(path),
                                   None if options is None else options.uv_primvar)
    for name, content in embedded.items():
        embed(name, content)
    return mesh
