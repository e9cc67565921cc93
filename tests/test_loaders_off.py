"""OFF loader: OFF, COFF, NOFF, STOFF, comments, header layouts, face lines."""

from pathlib import Path

import numpy as np
import pytest

from affinity.errors import MeshError
from affinity.loaders import load

DATA = Path(__file__).parent / "data" / "loaders"


def load_text(tmp_path, text, name="mesh.off"):
    path = tmp_path / name
    path.write_text(text)
    return load(path)


def test_fixture_quad_and_triangle():
    mesh = load(DATA / "square.off")
    assert mesh.face_sizes.tolist() == [4, 3]
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 3, 1, 4, 2]
    assert mesh.face_line.tolist() == [9, 10]
    np.testing.assert_array_equal(mesh.positions[4], [2, 0, 0])
    assert mesh.colors is None and mesh.texcoords is None and mesh.normals is None


@pytest.mark.parametrize(
    "header",
    ["OFF 3 1 0\n", "OFF\n3 1 0\n", "OFF\n\n# counts next\n3 1 0\n", "OFF # comment\n3 1\n"],
)
def test_header_layouts(tmp_path, header):
    mesh = load_text(tmp_path, header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    assert mesh.corner_vertex.tolist() == [0, 1, 2]
    assert mesh.face_line.tolist() == [header.count("\n") + 4]


def test_coff_integer_colours_scale_to_unit(tmp_path):
    mesh = load_text(tmp_path, "COFF\n3 1 0\n0 0 0 255 0 0\n1 0 0 0 255 0 255\n0 1 0 51 102 153\n3 0 1 2\n")
    np.testing.assert_allclose(mesh.colors, [[1, 0, 0], [0, 1, 0], [0.2, 0.4, 0.6]])


def test_coff_float_colours_are_kept(tmp_path):
    mesh = load_text(tmp_path, "COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 0 0.5 0 1\n0 1 0 0.25 0.25 0.25 1\n3 0 1 2 1 0 0\n")
    np.testing.assert_array_equal(mesh.colors, [[1, 0, 0], [0, 0.5, 0], [0.25, 0.25, 0.25]])


def test_noff_normals_are_per_vertex(tmp_path):
    mesh = load_text(tmp_path, "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 1 0\n0 1 0 1 0 0\n3 2 1 0\n")
    np.testing.assert_array_equal(mesh.normals, [[0, 0, 1], [0, 1, 0], [1, 0, 0]])
    assert mesh.corner_normal.tolist() == [2, 1, 0]


def test_stoff_texcoords(tmp_path):
    mesh = load_text(tmp_path, "STOFF\n4 1 0\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n")
    np.testing.assert_array_equal(mesh.texcoords, [[0, 0], [1, 0], [1, 1], [0, 1]])
    assert mesh.corner_texcoord.tolist() == [0, 1, 2, 3]


def test_stcnoff_order_of_vertex_fields(tmp_path):
    mesh = load_text(tmp_path, "STCNOFF\n3 1 0\n0 0 0 0 0 1 255 0 0 0.5 0.5\n1 0 0 0 0 1 0 0 255 1 0\n"
                               "0 1 0 0 0 1 0 255 0 0 1\n3 0 1 2\n")
    np.testing.assert_array_equal(mesh.normals[0], [0, 0, 1])
    np.testing.assert_array_equal(mesh.colors[1], [0, 0, 1])
    np.testing.assert_array_equal(mesh.texcoords[0], [0.5, 0.5])


def test_comments_and_face_colours(tmp_path):
    text = "OFF\n# c\n4 2 0\n0 0 0 # v0\n1 0 0\n\n1 1 0\n0 1 0\n# faces\n3 0 1 2 255 0 0\n3 0 2 3 0.5 0.5 0.5 1\n"
    mesh = load_text(tmp_path, text)
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 0, 2, 3]
    assert mesh.face_line.tolist() == [10, 11]


def test_mixed_face_sizes(tmp_path):
    mesh = load_text(tmp_path, "OFF\n6 3 0\n" + "0 0 0\n" * 6 + "3 0 1 2\n6 0 1 2 3 4 5\n4 5 4 3 2\n", name="MESH.OFF")
    assert mesh.counts() == {"faces": 3, "quads": 1, "triangles": 1, "ngons": 1}
    assert mesh.corner_vertex[-4:].tolist() == [5, 4, 3, 2]


def test_free_format_faces_wrap_over_lines(tmp_path):
    """OFF is free-format: a face's indices may continue on the next lines; its colour ends its last line."""
    text = "OFF\n5 3 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n4 0 1\n2 3\n3 1 4 2 255 0 0\n5\n0\n1 4 2 3\n"
    mesh = load_text(tmp_path, text)
    mesh.validate()
    assert mesh.face_start.tolist() == [0, 4, 7, 12]
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 3, 1, 4, 2, 0, 1, 4, 2, 3]
    assert mesh.face_line.tolist() == [8, 10, 11]


@pytest.mark.parametrize("text, line", [
    ("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0\n1 2\n3 0 1\n", 8),  # the second face runs out of numbers
    ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0\n1 2\n3 0 1 2\n", 8),  # more than the header declares
])
def test_free_format_faces_errors(tmp_path, text, line):
    with pytest.raises(MeshError) as caught:
        load_text(tmp_path, text)
    assert caught.value.line == line


def test_nan_colour_is_a_note_not_an_error(tmp_path):
    mesh = load_text(tmp_path, "COFF\n3 1 0\n0 0 0 255 0 0\n1 0 0 nan 0 0\n0 1 0 0 0 255\n3 0 1 2\n")
    assert mesh.colors is None and mesh.notes == ["1 vertex colour NaN (first at line 4): colours not checked"]
    np.testing.assert_array_equal(mesh.positions, [[0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(MeshError, match="not finite"):
        load_text(tmp_path, "COFF\n3 1 0\n0 0 0 255 0 0\n1 nan 0 0 0 0\n0 1 0 0 0 255\n3 0 1 2\n")
