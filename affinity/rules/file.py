"""Rules about the whole file: Q205 no-faces, Q902 missing-resource, and Q901 unreadable (reported, never linted)."""

from __future__ import annotations

import os

import numpy as np

from .families import QUAD_SHAPE
from .registry import RULES, Measured, Rule, page_fields, rule

FORMATS = (
    "The file formats read: Wavefront OBJ (Appendix B1 of the Advanced Visualizer manual, v/vt/vn/f), "
    "PLY (Turk 1994), OFF (Geomview), and USD's UsdGeom.Mesh schema."
)


@rule(code="Q205", name="no-faces", unit="vertices", scope="mesh", family=QUAD_SHAPE, references=FORMATS)
def no_faces(context) -> Measured:
    """The mesh has vertices but no faces.

    What it does:
        Flags a readable file that has vertices but no faces; the value reported is
        the number of vertices (the example's four v lines), on face -1 and line 1
        (no face to point at).

    Why it matters:
        Nothing will render; usually a broken export (point cloud, lost face block).

    Example:
        # only v lines: a point cloud, or an export that lost its faces
        v 0 0 0
        v 2 0 0
        v 2 1 0
        v 0 1 0

    Prints:
        example.obj:1:1: Q205 warning no-faces: the mesh has vertices but no faces (4 vertices)

    Use instead:
        # the same vertices exported with their face
        v 0 0 0
        v 2 0 0
        v 2 1 0
        v 0 1 0
        f 1 2 3 4

    How to fix:
        Re-export the mesh with faces enabled in the exporter's geometry options.
    """
    mesh = context.mesh
    if mesh.n_faces or not len(mesh.positions):
        return Measured.nothing()
    return Measured(np.array([0]), np.array([float(len(mesh.positions))]), lines=np.array([1]))


def unusable_resource(path: str, image: bool) -> str | None:
    """Why the resource at ``path`` cannot be used (``"not found"``, ``"is a FIFO (named pipe), not a
    regular file: not read"``, over the side-file budget: an image is read in part, others whole), or None."""
    from ..loaders import LFS_POINTER
    from ..loaders.imagesize import image_size
    from ..loaders.regular import SIDE_FILE_BUDGET, RefusedFile
    from ..loaders.sidefiles import open_side_file

    try:
        with open_side_file(path, None if image else SIDE_FILE_BUDGET) as fh:
            head = fh.read(len(LFS_POINTER))
    except FileNotFoundError:
        return "not found"
    except RefusedFile as err:
        return err.strerror
    except OSError as err:
        return f"cannot be read ({err.strerror or err})"
    if head == LFS_POINTER:
        return "is a Git LFS pointer (run git lfs pull)"
    if image and image_size(path) is None:
        return "is not a PNG, JPEG, BMP or TGA image"
    return None


@rule(code="Q902", name="missing-resource", level="info", scope="mesh", family=QUAD_SHAPE,
      references="Wavefront OBJ and MTL (Advanced Visualizer manual, Appendix B1 and B2: mtllib, map_Kd).")
def missing_resources(context) -> Measured:
    """An mtllib or map_Kd named by the file cannot be found or read.

    What it does:
        Reports, once per file and resource, an mtllib library or a map_Kd texture
        (or a file of any other role in the resource registry) that is missing,
        unreadable, not an image, or a Git LFS pointer. Q101's texel unit then comes
        from the texture-size setting, and the finding says so.

    Why it matters:
        Without the texture the same quad reads a different number of texels (a
        shift of a quarter of the texture's width is 256 texels with texture-size
        1024, 1024 with a 4096 texture): the finding keeps the unit from changing
        behind the user's back. A checkout without textures is
        common in CI, so it is info and does not fail the gate by itself.

    Example:
        # a material library that is not there
        mtllib missing.mtl
        v 0 0 0
        v 2 0 0
        v 0 2 0
        f 1 2 3

    Prints:
        example.obj:2:1: Q902 info missing-resource: an mtllib or map_Kd named by the file cannot be found or read: mtllib missing.mtl not found

    Use instead:
        # the same mesh without the line naming a library it does not need (one file cannot ship one)
        v 0 0 0
        v 2 0 0
        v 0 2 0
        f 1 2 3

    How to fix:
        Add the file next to the mesh (git lfs pull for LFS pointers), fix the
        name in the mtllib or map_Kd line, or, where the mesh needs no material,
        drop the line (re-export without materials).
    """
    # The files the loader found referenced (``mesh.resources``, the resource registry's
    # roles), each looked at once; a USD stage's layers are pxr's to compose, and their
    # changes reach the cache, but a missing one is not a finding (Q902 is about OBJ and MTL). A finding sits on the line that pulls the file in
    # (face -1); its detail names the resource and, where the texel unit would have come
    # from that texture, the texture-size used instead.
    from ..loaders.names import printable  # names come from the file: never send its control characters
    from ..loaders.resources import ROLES

    mesh, settings = context.mesh, context.settings
    folder = os.path.dirname(mesh.path)
    texels = mesh.texcoords is not None and "Q101" in RULES
    fallback = f"; texels use texture-size {settings.texture_size}"
    used = {mesh.material_names[m] for m in np.unique(mesh.face_material) if m >= 0}  # materials faces bind
    lines, details, seen = [], [], set()
    for resource in mesh.resources:
        role = ROLES.get(resource.role)
        if role is None or role.named_in == "usd" or resource.path in seen:
            continue
        seen.add(resource.path)
        problem = unusable_resource(resource.path, image=role.image)
        if not problem:
            continue
        lines.append(resource.line)
        if resource.library is None:
            texture_unit_lost = texels and not mesh.material_textures and role.name == "mtllib"
            details.append(f"{role.statement} {printable(resource.name)} {problem}"
                           + (fallback if texture_unit_lost else ""))
        else:
            shown = os.path.relpath(resource.path, folder) if folder else resource.path
            details.append(f"{role.statement} {printable(shown)} (in {printable(resource.library)}) {problem}"
                           + (fallback if texels and role.texture == "base colour" and resource.material in used
                              else ""))
    n = len(lines)
    return Measured(np.zeros(n, dtype=np.int64), np.zeros(n), lines=np.array(lines, dtype=np.int64), details=details)


UNREADABLE_PAGE = """File cannot be parsed.

What it does:
    Reports a file that cannot be read as a mesh, with the line. It is not a lint
    finding: the message goes to stderr, the exit code is 2, and --select/--ignore
    do not apply to it. The example's face, on line 5, names vertex 4 of a file
    with 3.

Why it matters:
    Nothing in it can be checked.

Example:
    # a face that names a vertex the file does not have
    v 0 0 0
    v 1 0 0
    v 1 1 0
    f 1 2 3 4

Prints:
    example.obj:5: Q901 unreadable: vertex index out of range (the file has 3)

Use instead:
    # the same face with the vertex it names
    v 0 0 0
    v 1 0 0
    v 1 1 0
    v 0 1 0
    f 1 2 3 4

How to fix:
    Re-export the file from the modelling tool.
"""

#: Q901 is not a lint rule (design.md): documented like one, never registered.
UNREADABLE = Rule(code="Q901", name="unreadable", level="error", scope="mesh", family=QUAD_SHAPE, references=FORMATS,
                  **page_fields(UNREADABLE_PAGE))
