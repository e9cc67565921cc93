"""OBJ files read in chunks: the mesh must not depend on where the chunks end.

Generated valid OBJ files mix face sizes and corner forms (attributes on some
faces only, empty trailing slots), groups, materials, comments, colours,
negative indices and '\\' continuations, in runs, so that chunk boundaries fall
between runs of one face size and runs of several. Each file is parsed whole,
at chunk sizes down to three bytes, and by the plain line-by-line reader below,
which shares no code with the loader.
"""

import random

import numpy as np
import pytest
from helpers.generated_obj import FIELDS, generate_obj
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from affinity.loaders.obj import load_obj

CHUNK_SIZES = (4096, 257, 61, 13, 3)








def reference_parse(text: str) -> dict:
    """The mesh of an OBJ file, one statement at a time, in plain Python."""
    v, vt, vn, colors, has_color = [], [], [], [], False
    face_start, corner = [0], {"v": [], "vt": [], "vn": []}
    face_line, face_group, face_material = [], [], []
    groups, materials = {}, {}
    obj = group = ""
    material = None
    physical = text.split("\n")
    number = 0
    while number < len(physical):
        first = number + 1
        line = physical[number]
        number += 1
        while line.endswith("\\") and number < len(physical):
            line = line[:-1] + " " + physical[number]
            number += 1
        words = line.split()
        words = words[: next((k for k, w in enumerate(words) if w.startswith("#")), len(words))]
        if not words:
            continue
        key, rest = words[0], words[1:]
        if key == "v":
            v.append([float(x) for x in rest[:3]])
            colors.append([float(x) for x in rest[3:6]] if len(rest) >= 6 else [1.0, 1.0, 1.0])
            has_color |= len(rest) >= 6
        elif key == "vt":
            uv = [float(x) for x in rest[:2]]
            vt.append(uv + [0.0] * (2 - len(uv)))
        elif key == "vn":
            vn.append([float(x) for x in rest])
        elif key == "f":
            for word in rest:
                slots = word.split("/") + ["", ""]
                for name, token, elements in zip(("v", "vt", "vn"), slots, (v, vt, vn)):
                    if not token:
                        corner[name].append(-1)
                        continue
                    k = int(token)
                    corner[name].append(len(elements) + k if k < 0 else k - 1)
            face_start.append(face_start[-1] + len(rest))
            face_line.append(first)
            face_group.append(groups.setdefault(group or obj, len(groups)))
            face_material.append(-1 if material is None else materials[material])
        elif key == "o":
            obj, group = " ".join(rest), ""
        elif key == "g":
            group = " ".join(rest)
        elif key == "usemtl":
            material = " ".join(rest)
            materials.setdefault(material, len(materials))
    return {
        "positions": np.array(v, dtype=float).reshape(-1, 3),
        "colors": np.array(colors).reshape(-1, 3) if has_color else None,
        "texcoords": np.array(vt).reshape(-1, 2) if vt else None,
        "normals": np.array(vn).reshape(-1, 3) if vn else None,
        "face_start": np.array(face_start),
        "corner_vertex": np.array(corner["v"], dtype=np.int64),
        "corner_texcoord": np.array(corner["vt"], dtype=np.int64) if vt else None,
        "corner_normal": np.array(corner["vn"], dtype=np.int64) if vn else None,
        "face_line": np.array(face_line, dtype=np.int64),
        "face_group": np.array(face_group, dtype=np.int32),
        "group_names": list(groups) or [""],
        "face_material": np.array(face_material, dtype=np.int32),
        "material_names": list(materials),
    }




def assert_same_mesh(mesh, expected: dict, where: str) -> None:
    for name in FIELDS:
        got, want = getattr(mesh, name), expected[name]
        assert (got is None) == (want is None), f"{where}: {name} is {got!r}, expected {want!r}"
        if want is not None:
            np.testing.assert_array_equal(got, want, err_msg=f"{where}: {name}")
    assert mesh.group_names == expected["group_names"], where
    assert mesh.material_names == expected["material_names"], where
    assert (mesh.colors is None) == (expected["colors"] is None), f"{where}: colors"
    if expected["colors"] is not None:
        np.testing.assert_array_equal(mesh.colors, expected["colors"], err_msg=f"{where}: colors")
    mesh.validate()


@pytest.mark.slow  # 30 generated files, each read at every chunk size
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(seed=st.integers(0, 2**32 - 1))
def test_chunk_size_never_changes_the_mesh(tmp_path, seed):
    text = generate_obj(random.Random(seed))
    path = tmp_path / f"generated_{seed}.obj"
    path.write_text(text)
    expected = reference_parse(text)
    assert_same_mesh(load_obj(path), expected, "one chunk")
    for size in CHUNK_SIZES:
        assert_same_mesh(load_obj(path, chunk_bytes=size), expected, f"chunks of {size} bytes")


def test_quads_after_a_mixed_chunk_are_kept(tmp_path):
    """The reported case: a part mixing triangles and quads, then a part of triangles only."""
    vertices = "".join(f"v {k} {k % 7} 0\n" for k in range(8))
    mixed = "f 1 2 3 4\nf 1 2 3\n" * 1000
    triangles = "f 2 3 4\n" * 3000
    path = tmp_path / "mixed_then_triangles.obj"
    path.write_text(vertices + mixed + triangles)
    for size in (None, 1 << 12, 100):
        counts = load_obj(path, chunk_bytes=size).counts()
        assert counts == {"faces": 5000, "quads": 1000, "triangles": 4000, "ngons": 0}, size


def test_a_material_library_is_found_in_any_chunk(tmp_path):
    """The reader searches the bytes for ``mtllib`` statements only when a chunk may hold one: the
    libraries are those :func:`~affinity.loaders.resources.mtllib_statements` finds in the whole file,
    wherever the chunks end, and a comment naming the word is no statement."""
    from affinity.loaders.resources import mtllib_statements

    (tmp_path / "late.mtl").write_text("newmtl red\nKd 1 0 0\n")
    grid = "".join(f"v {k % 10}.5 {k // 10}.25 0.0\n" for k in range(400))
    faces = "".join(f"f {k + 1} {k + 2} {k + 12} {k + 11}\n" for k in range(0, 380, 2))
    text = "# mtllib commented.mtl\n" + grid + faces + "mtllib late.mtl\nusemtl red\n" + faces
    path = tmp_path / "late_library.obj"
    path.write_text(text)
    assert [name for _, name in mtllib_statements(text.encode())] == ["late.mtl"]
    for size in (None, 1 << 12, 257, 61):
        resources = load_obj(path, chunk_bytes=size).resources
        assert [(r.role, r.name, r.line) for r in resources] == [("mtllib", "late.mtl", 592)], size
    plain = tmp_path / "no_library.obj"
    plain.write_text(grid + faces)
    assert load_obj(plain).resources == []
