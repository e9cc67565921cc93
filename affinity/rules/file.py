"""Rules about the whole file: Q205 no-faces, and Q901 unreadable (reported, never linted)."""

from __future__ import annotations

import numpy as np

from .registry import Rule, page_fields, rule

FORMATS = (
    "The file formats read: Wavefront OBJ (Appendix B1 of the Advanced Visualizer manual, v/vt/vn/f), "
    "PLY (Turk 1994), OFF (Geomview), and USD's UsdGeom.Mesh schema."
)


@rule(code="Q205", name="no-faces", scope="mesh", references=FORMATS)
def no_faces(mesh, settings) -> tuple | None:
    """The mesh has vertices but no faces.

    What it does:
        Flags a readable file that has vertices but no faces; the value reported is
        the number of vertices, on face -1 and line 1 (no face to point at).

    Why it matters:
        Nothing will render; usually a broken export (point cloud, lost face block).

    Example:
        # only v lines: a point cloud, or an export that lost its faces
        v 0 0 0
        v 1 0 0
        v 1 1 0
        v 0 1 0

    Prints:
        example.obj:1:1: Q205 no-faces: the mesh has vertices but no faces (4)

    How to fix:
        Re-export the mesh with faces enabled in the exporter's geometry options.
    """
    if mesh.n_faces or not len(mesh.positions):
        return None
    return np.array([-1]), np.array([1]), np.array([float(len(mesh.positions))])


UNREADABLE_PAGE = """File cannot be parsed.

What it does:
    Reports a file that cannot be read as a mesh, with the line. It is not a lint
    finding: the message goes to stderr, the exit code is 2, and --select/--ignore
    do not apply to it.

Why it matters:
    Nothing in it can be checked.

Example:
    # a face that names a vertex the file does not have
    v 0 0 0
    v 1 0 0
    v 1 1 0
    f 1 2 3 4

How to fix:
    Re-export the file from the modelling tool.
"""

#: Q901 is not a lint rule (design.md): documented like one, never registered.
UNREADABLE = Rule(code="Q901", name="unreadable", level="error", scope="mesh", references=FORMATS,
                  **page_fields(UNREADABLE_PAGE))
