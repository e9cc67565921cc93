"""Rules about the whole file: Q205 no-faces, and Q901 unreadable (reported, never linted)."""

from __future__ import annotations

import numpy as np

from .registry import Rule, register

FORMATS = (
    "The file formats read: Wavefront OBJ (Appendix B1 of the Advanced Visualizer manual, v/vt/vn/f), "
    "PLY (Turk 1994), OFF (Geomview), and USD's UsdGeom.Mesh schema."
)


def no_faces(mesh, settings) -> tuple | None:
    """Q205: the number of vertices of a mesh without faces, on face -1, line 1 (no face to point at)."""
    if mesh.n_faces or not len(mesh.positions):
        return None
    return np.array([-1]), np.array([1]), np.array([float(len(mesh.positions))])


register(Rule(
    code="Q205", name="no-faces",
    summary="the mesh has vertices but no faces", scope="mesh",
    check=no_faces,
    what=(
        "Flags a readable file that has vertices but no faces; the value reported "
        "is the number of vertices."
    ),
    why="Nothing will render; usually a broken export (point cloud, lost face block).",
    example="# only v lines: a point cloud, or an export that lost its faces\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n",
    example_output='example.obj:1:1: Q205 no-faces: the mesh has vertices but no faces (4)\n',
    fix="Re-export the mesh with faces enabled in the exporter's geometry options.",
    references=FORMATS,
))

#: Q901 is not a lint rule (design.md): its message goes to stderr, the exit code
#: is 2, and --select/--ignore do not apply. It is documented like one.
UNREADABLE = Rule(
    code="Q901", name="unreadable", summary="file cannot be parsed", level="error", scope="mesh",
    what=(
        "Reports a file that cannot be read as a mesh, with the line. It is not a lint "
        "finding: the message goes to stderr, the exit code is 2, and --select/--ignore "
        "do not apply to it."
    ),
    why="Nothing in it can be checked.",
    example="# a face that names a vertex the file does not have\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3 4\n",
    example_output="",
    fix="Re-export the file from the modelling tool.",
    references=FORMATS,
)
