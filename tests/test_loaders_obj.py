"""Wavefront OBJ loader: face forms, indices, attributes, groups, materials, line numbers."""

from pathlib import Path

import numpy as np
import pytest

from affinity.errors import MeshError
from affinity.loaders import load
from affinity.loaders import text as loader_text

DATA = Path(__file__).parent / "data" / "loaders"

SQUARE = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"


def write(tmp_path, body, name="mesh.obj", mode="w"):
    path = tmp_path / name
    if mode == "w":
        path.write_text(body)
    else:
        path.write_bytes(body)
    return path


def test_vertex_only_faces(tmp_path):
    mesh = load(write(tmp_path, SQUARE + "f 1 2 3 4\n"))
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 3]
    assert mesh.face_start.tolist() == [0, 4]
    assert mesh.texcoords is None and mesh.corner_texcoord is None
    assert mesh.normals is None and mesh.corner_normal is None
    np.testing.assert_array_equal(mesh.positions[2], [1, 1, 0])


def test_vertex_texcoord_faces(tmp_path):
    body = SQUARE + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt .5 .25\nf 1/5 2/4 3/3 4/2\n"
    mesh = load(write(tmp_path, body))
    assert mesh.corner_texcoord.tolist() == [4, 3, 2, 1]
    np.testing.assert_array_equal(mesh.texcoords[4], [0.5, 0.25])
    assert mesh.corner_normal is None


def test_vertex_normal_faces(tmp_path):
    mesh = load(write(tmp_path, SQUARE + "vn 0 0 1\nvn 0 0 -1\nf 1//2 2//1 3//2 4//1\n"))
    assert mesh.corner_normal.tolist() == [1, 0, 1, 0]
    assert mesh.corner_texcoord is None
    np.testing.assert_array_equal(mesh.normals[1], [0, 0, -1])


def test_full_corner_faces(tmp_path):
    body = SQUARE + "vt 0 0\nvt 1 0\nvn 0 0 1\nf 1/2/1 2/1/1 3/2/1 4/1/1\n"
    mesh = load(write(tmp_path, body))
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 3]
    assert mesh.corner_texcoord.tolist() == [1, 0, 1, 0]
    assert mesh.corner_normal.tolist() == [0, 0, 0, 0]


def test_faces_of_different_forms_in_one_file(tmp_path):
    body = SQUARE + "vt 0 0\nvn 0 0 1\nf 1 2 3\nf 1/1 3/1 4/1\nf 1//1 2//1 4//1\n"
    mesh = load(write(tmp_path, body))
    assert mesh.corner_texcoord.tolist() == [-1, -1, -1, 0, 0, 0, -1, -1, -1]
    assert mesh.corner_normal.tolist() == [-1, -1, -1, -1, -1, -1, 0, 0, 0]


def test_negative_indices_count_back_from_the_line(tmp_path):
    body = SQUARE + "vt 0 0\nvt 1 1\nf -4/-2 -3/-1 -2/-2\nv 5 5 5\nf -1 -5 -4\n"
    mesh = load(write(tmp_path, body))
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 4, 0, 1]
    assert mesh.corner_texcoord.tolist() == [0, 1, 0, -1, -1, -1]


def test_negative_indices_across_chunks(tmp_path, monkeypatch):
    monkeypatch.setattr(loader_text, "CHUNK_BYTES", 64)
    lines = [f"v {k} 0 0" for k in range(40)] + ["f -1 -2 -3"] + [f"v {k} 1 0" for k in range(40)] + ["f -1 -2 -3 1"]
    mesh = load(write(tmp_path, "\n".join(lines) + "\n"))
    assert mesh.corner_vertex.tolist() == [39, 38, 37, 79, 78, 77, 0]
    assert mesh.face_line.tolist() == [41, 82]


def test_forward_reference_is_allowed(tmp_path):
    mesh = load(write(tmp_path, "f 1 2 3\n" + SQUARE))
    assert mesh.corner_vertex.tolist() == [0, 1, 2]


def test_ngons_and_triangles_are_kept(tmp_path):
    body = SQUARE + "v 2 0 0\nv 2 1 0\nf 1 2 3\nf 1 2 5 6 3 4\nf 1 2 3 4\n"
    mesh = load(write(tmp_path, body))
    assert mesh.face_sizes.tolist() == [3, 6, 4]
    assert mesh.counts() == {"faces": 3, "quads": 1, "triangles": 1, "ngons": 1}


def test_face_line_numbers_skip_comments_and_blank_lines(tmp_path):
    body = "# header\n\n" + SQUARE + "\n# faces\nf 1 2 3\n\n\nf 1 3 4\n"
    mesh = load(write(tmp_path, body))
    assert mesh.face_line.tolist() == [9, 12]


def test_crlf_tabs_and_trailing_comments(tmp_path):
    body = "v\t0 0 0\r\nv 1 0 0 # corner\r\nv 1\t1 0\r\nv 0 1 0\r\nf 1 2 3 4 # quad\r\n"
    mesh = load(write(tmp_path, body.encode(), mode="wb"))
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 3]
    assert mesh.face_line.tolist() == [5]
    np.testing.assert_array_equal(mesh.positions[2], [1, 1, 0])


def test_line_continuation_joins_lines_and_keeps_numbering(tmp_path):
    body = SQUARE + "f 1 2 \\\n 3 4\nf 1 \\\r\n 2 3\nv 9 9 9\nf 5 1 2\n"
    mesh = load(write(tmp_path, body.encode(), mode="wb"))
    assert mesh.face_sizes.tolist() == [4, 3, 3]
    assert mesh.face_line.tolist() == [5, 7, 10]


def test_continuation_on_the_last_line(tmp_path):
    for ending in ("f 1 2 3 \\\n", "f 1 2 \\\n3", "f 1 2 3 \\"):
        mesh = load(write(tmp_path, SQUARE + ending))
        assert mesh.corner_vertex.tolist() == [0, 1, 2] and mesh.face_line.tolist() == [5]


def test_no_trailing_newline(tmp_path):
    mesh = load(write(tmp_path, SQUARE + "f 1 2 3 4"))
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 3]


def test_numbers_in_every_notation(tmp_path):
    body = "v -1.5 +2 3e-2\nv .5 5. -0.000001\nv 1E3 -7.25e+1 123456789.123456\nf 1 2 3\n"
    mesh = load(write(tmp_path, body))
    expected = [[-1.5, 2, 0.03], [0.5, 5, -1e-6], [1000, -72.5, 123456789.123456]]
    np.testing.assert_array_equal(mesh.positions, expected)


def test_vertex_colours(tmp_path):
    body = "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1\nv 0 1 0 0.5 0.5 0.5\nf 1 2 3 4\n"
    mesh = load(write(tmp_path, body))
    np.testing.assert_array_equal(mesh.colors, [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.5, 0.5, 0.5]])
    np.testing.assert_array_equal(mesh.positions[1], [1, 0, 0])


def test_homogeneous_w_is_not_a_colour(tmp_path):
    mesh = load(write(tmp_path, "v 0 0 0 1\nv 1 0 0 1\nv 1 1 0 0.5\nf 1 2 3\n"))
    assert mesh.colors is None
    np.testing.assert_array_equal(mesh.positions[2], [1, 1, 0])


def test_seven_numbers_are_colour_plus_ignored_alpha(tmp_path):
    mesh = load(write(tmp_path, "v 0 0 0 0.1 0.2 0.3 1\nv 1 0 0\nv 1 1 0\nf 1 2 3\n"))
    np.testing.assert_array_equal(mesh.colors, [[0.1, 0.2, 0.3], [1, 1, 1], [1, 1, 1]])


def test_mixed_vertex_widths_across_chunks(tmp_path, monkeypatch):
    monkeypatch.setattr(loader_text, "CHUNK_BYTES", 16)
    body = "v 0 0 0 0.5\nv 1 0 0\nv 1 1 0 0.25 0.5 0.75\nv 0 1 0 0.9\nf 1 2 3 4\n"
    mesh = load(write(tmp_path, body))
    np.testing.assert_array_equal(mesh.colors, [[1, 1, 1], [1, 1, 1], [0.25, 0.5, 0.75], [1, 1, 1]])
    np.testing.assert_array_equal(mesh.positions[3], [0, 1, 0])


def test_texcoord_with_one_or_three_numbers(tmp_path):
    mesh = load(write(tmp_path, SQUARE + "vt 0.25\nvt 0.5 0.75 1\nf 1/1 2/2 3/1\n"))
    np.testing.assert_array_equal(mesh.texcoords, [[0.25, 0], [0.5, 0.75]])


def test_unknown_and_ignored_statements(tmp_path):
    body = SQUARE + "s 1\nl 1 2\np 3\nvp 0.5\ncstype bezier\nf 1 2 3 4\ns off\n"
    mesh = load(write(tmp_path, body))
    assert mesh.counts()["quads"] == 1


def test_groups_objects_materials_and_textures():
    mesh = load(DATA / "textured_quads.obj")
    assert mesh.group_names == ["left", "right"]
    assert mesh.face_group.tolist() == [0, 1]
    assert mesh.material_names == ["wood", "stone"]
    assert mesh.face_material.tolist() == [0, 1]
    assert mesh.material_textures == {"wood": str(DATA / "textures" / "wood.png")}
    assert mesh.face_line.tolist() == [19, 22]
    assert mesh.corner_texcoord.tolist() == [0, 1, 2, 3, 0, 1, 4, 3]


def test_object_name_is_the_group_when_there_is_no_g(tmp_path):
    body = SQUARE + "f 1 2 3\no body\nf 1 3 4\ng part\nf 2 3 4\no other\nf 1 2 4\n"
    mesh = load(write(tmp_path, body))
    assert mesh.group_names == ["", "body", "part", "other"]
    assert mesh.face_group.tolist() == [0, 1, 2, 3]
    assert mesh.face_material.tolist() == [-1, -1, -1, -1]


def test_missing_mtl_is_not_an_error(tmp_path):
    mesh = load(write(tmp_path, "mtllib nowhere.mtl\n" + SQUARE + "usemtl red\nf 1 2 3 4\n"))
    assert mesh.material_names == ["red"] and mesh.material_textures == {}


def test_vertices_without_faces(tmp_path):
    mesh = load(write(tmp_path, SQUARE))
    assert mesh.n_faces == 0 and len(mesh.positions) == 4
    assert mesh.counts() == {"faces": 0, "quads": 0, "triangles": 0, "ngons": 0}


def test_latin1_in_comments_is_accepted(tmp_path):
    mesh = load(write(tmp_path, b"# caf\xe9\n" + SQUARE.encode() + b"f 1 2 3\n", mode="wb"))
    assert mesh.face_line.tolist() == [6]


def test_many_chunks_match_one_chunk(tmp_path, monkeypatch):
    rng = np.random.default_rng(1)
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in rng.normal(size=(50, 3))]
    lines += [f"vt {u:.4f} {v:.4f}" for u, v in rng.random((30, 2))]
    lines += ["g a", "usemtl m"] + [f"f {a}/{b} {c}/{d} {e}/{b}" for a, c, e, b, d in rng.integers(1, 30, size=(40, 5))]
    path = write(tmp_path, "\n".join(lines) + "\n")
    whole = load(path)
    monkeypatch.setattr(loader_text, "CHUNK_BYTES", 37)
    pieces = load(path)
    for name in ("positions", "texcoords", "corner_vertex", "corner_texcoord", "face_start", "face_line", "face_group"):
        np.testing.assert_array_equal(getattr(whole, name), getattr(pieces, name))
    np.testing.assert_array_equal(whole.positions, np.array([line.split()[1:] for line in lines[:50]], dtype=float))


def test_number_parsing_matches_python_float(tmp_path):
    """Random decimals of every length and sign parse exactly as Python's float() does."""
    rng = np.random.default_rng(3)
    texts = []
    for _ in range(3000):
        digits = "".join(rng.choice(list("0123456789"), size=rng.integers(1, 16)))
        dot = rng.integers(-1, len(digits) + 1)  # -1: no dot
        text = digits if dot < 0 else digits[:dot] + "." + digits[dot:]
        texts.append(rng.choice(["", "-", "+"]) + text)
    texts += ["-0", "0.", ".0", "12345678.87654321", "-9999999999.99999", "1e-3", "-2.5E+2"]
    rows = [texts[k : k + 3] for k in range(0, len(texts) - 2, 3)]
    body = "".join(f"v {' '.join(row)}\n" for row in rows)
    mesh = load(write(tmp_path, body))
    np.testing.assert_array_equal(mesh.positions, [[float(t) for t in row] for row in rows])


def test_empty_trailing_slots(tmp_path):
    """``v//``, ``v/vt/`` and ``v/`` name no more than the slots they fill (tinyobjloader, Blender read them)."""
    body = SQUARE + "vt 0 0\nvt 1 1\nvn 0 0 1\nf 1// 2// 3//\nf 1/2/ 2/1/ 3/2/ 4/1/\nf 1/\t2/\t4/\nf 2//1 3//1 4//1\n"
    mesh = load(write(tmp_path, body))
    assert mesh.face_start.tolist() == [0, 3, 7, 10, 13]
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 0, 1, 2, 3, 0, 1, 3, 1, 2, 3]
    assert mesh.corner_texcoord.tolist() == [-1] * 3 + [1, 0, 1, 0] + [-1] * 6
    assert mesh.corner_normal.tolist() == [-1] * 10 + [0] * 3
    mesh.validate()


def test_empty_slots_in_uniform_lines_are_read_per_line(tmp_path):
    """'1/  2' (one empty slot, two spaces) and '1// 2' have gaps of one length: each line is read as written."""
    body = SQUARE + "vt 0 0\nf 1/1/  2/1/  3/1/\nf 1/1// 2/1// 3/1//\n"
    path = write(tmp_path, body)
    with pytest.raises(MeshError) as info:
        load(path)
    error = info.value
    assert error.line == 7 and "malformed" in error.reason


def test_latin1_names(tmp_path):
    """A name in an 8-bit code page is text (Latin-1 when it is not UTF-8); only numbers must parse."""
    body = SQUARE.encode() + b"g caf\xe9\nusemtl m\xe4t\nf 1 2 3\ng \xc3\xa9t\xc3\xa9\nf 1 3 4\n"
    mesh = load(write(tmp_path, body, mode="wb"))
    assert mesh.group_names == ["caf\xe9", "\xe9t\xe9"]
    assert mesh.material_names == ["m\xe4t"]
    assert mesh.face_group.tolist() == [0, 1]


def test_nan_colour_is_a_note_not_an_error(tmp_path):
    body = "v 0 0 0 1 0 0\nv 1 0 0 nan 0 0\nv 1 1 0 0 1 nan\nv 0 1 0 0 0 1\nf 1 2 3 4\n"
    mesh = load(write(tmp_path, body))
    assert mesh.colors is None and mesh.notes == ["2 vertex colours NaN (first at line 2): colours not checked"]
    np.testing.assert_array_equal(mesh.positions, [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    with pytest.raises(MeshError, match="finite"):
        load(write(tmp_path, "v 0 0 0 1 0 0\nv nan 0 0 1 0 0\nv 1 1 0 0 1 0\nf 1 2 3\n"))
