"""PLY loader: ASCII, binary little- and big-endian give the same mesh; attributes; skipping."""

import warnings
from pathlib import Path

import numpy as np
import pytest

from affinity.errors import MeshError, SkippedFile
from affinity.loaders import load

DATA = Path(__file__).parent / "data" / "loaders"
FORMATS = ["ascii", "binary_little_endian", "binary_big_endian"]


def write_ply(path, fmt, elements):
    """Write a PLY file with our own minimal writer.

    elements: list of (name, properties, rows); properties are ("type", name) or
    ("list", count type, item type, name); rows are tuples (lists for list properties).
    """
    header = ["ply", f"format {fmt} 1.0", "comment written by tests/test_loaders_ply.py"]
    for name, properties, rows in elements:
        header.append(f"element {name} {len(rows)}")
        header += [f"property {' '.join(p)}" for p in properties]
    header.append("end_header")
    body = bytearray()
    order = ">" if fmt == "binary_big_endian" else "<"
    codes = {"char": "i1", "uchar": "u1", "short": "i2", "ushort": "u2", "int": "i4", "uint": "u4", "float": "f4",
             "double": "f8"}
    text_rows = []
    for _, properties, rows in elements:
        for row in rows:
            words = []
            for prop, value in zip(properties, row):
                if prop[0] == "list":
                    words += [str(len(value))] + [repr(v) for v in value]
                    body += np.array([len(value)], order + codes[prop[1]]).tobytes()
                    body += np.array(value, order + codes[prop[2]]).tobytes()
                else:
                    words.append(repr(value))
                    body += np.array([value], order + codes[prop[0]]).tobytes()
            text_rows.append(" ".join(words))
    with open(path, "wb") as fh:
        fh.write(("\n".join(header) + "\n").encode())
        fh.write(("\n".join(text_rows) + "\n").encode() if fmt == "ascii" else bytes(body))
    return path


VERTEX = [("float", "x"), ("float", "y"), ("float", "z"), ("float", "nx"), ("float", "ny"), ("float", "nz"),
          ("uchar", "red"), ("uchar", "green"), ("uchar", "blue"), ("uchar", "alpha"),
          ("float", "s"), ("float", "t")]  # fmt: skip
VERTEX_ROWS = [
    (0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 255, 0, 0, 255, 0.0, 0.0),
    (1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0, 255, 0, 255, 1.0, 0.0),
    (1.0, 1.0, 0.5, 0.0, 0.6, 0.8, 0, 0, 255, 255, 1.0, 1.0),
    (0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 51, 102, 153, 255, 0.0, 1.0),
    (2.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0, 0, 0, 0, 0.5, 0.25),
]
FACE = [("list", "uchar", "int", "vertex_indices"), ("int", "flags")]
FACE_ROWS = [([0, 1, 2, 3], 7), ([1, 4, 2], 8), ([0, 1, 4, 2, 3], 9)]
EDGE = [("int", "vertex1"), ("int", "vertex2"), ("list", "ushort", "double", "weights")]
EDGE_ROWS = [(0, 1, [0.5, 0.25, 1.0]), (1, 2, [])]


def sample(tmp_path, fmt):
    elements = [("vertex", VERTEX, VERTEX_ROWS), ("edge", EDGE, EDGE_ROWS), ("face", FACE, FACE_ROWS)]
    return load(write_ply(tmp_path / f"{fmt}.ply", fmt, elements))


@pytest.mark.parametrize("fmt", FORMATS)
def test_attributes(tmp_path, fmt):
    mesh = sample(tmp_path, fmt)
    np.testing.assert_array_equal(mesh.positions, [r[:3] for r in VERTEX_ROWS])
    np.testing.assert_allclose(mesh.normals, [r[3:6] for r in VERTEX_ROWS], rtol=1e-7)
    np.testing.assert_allclose(mesh.colors, np.array([r[6:9] for r in VERTEX_ROWS]) / 255)
    np.testing.assert_array_equal(mesh.texcoords, [r[10:] for r in VERTEX_ROWS])
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 3, 1, 4, 2, 0, 1, 4, 2, 3]
    assert mesh.face_sizes.tolist() == [4, 3, 5]
    assert mesh.corner_texcoord.tolist() == mesh.corner_vertex.tolist()
    assert mesh.corner_normal.tolist() == mesh.corner_vertex.tolist()


def test_three_encodings_give_identical_arrays(tmp_path):
    meshes = [sample(tmp_path, fmt) for fmt in FORMATS]
    for name in ("positions", "normals", "colors", "texcoords", "face_start", "corner_vertex", "corner_texcoord"):
        for other in meshes[1:]:
            np.testing.assert_array_equal(getattr(meshes[0], name), getattr(other, name))


@pytest.mark.parametrize("fmt", FORMATS)
def test_face_lines(tmp_path, fmt):
    # header: ply, format, comment, then each element line with its property lines, end_header;
    # the ASCII face rows follow the 5 vertex and 2 edge rows
    mesh = sample(tmp_path, fmt)
    header_lines = 3 + 1 + len(VERTEX) + 1 + len(EDGE) + 1 + len(FACE) + 1
    expected = [header_lines + 5 + 2 + k + 1 for k in range(3)] if fmt == "ascii" else [0, 0, 0]
    assert mesh.face_line.tolist() == expected


@pytest.mark.parametrize("fmt", FORMATS)
def test_per_face_texcoord_lists(tmp_path, fmt):
    vertex = [("double", "x"), ("double", "y"), ("double", "z")]
    face = [("list", "int", "uint", "vertex_index"), ("list", "uchar", "float", "texcoord")]
    rows = [([0, 1, 2, 3], [0, 0, 0.5, 0, 0.5, 0.5, 0, 0.5]), ([1, 4, 2], [0.5, 0, 1, 0, 1, 0.5])]
    path = write_ply(tmp_path / "uv.ply", fmt, [("vertex", vertex, [r[:3] for r in VERTEX_ROWS]), ("face", face, rows)])
    mesh = load(path)
    np.testing.assert_array_equal(mesh.texcoords, np.array(rows[0][1] + rows[1][1]).reshape(-1, 2))
    assert mesh.corner_texcoord.tolist() == list(range(7))
    assert mesh.corner_vertex.tolist() == [0, 1, 2, 3, 1, 4, 2]
    assert mesh.colors is None and mesh.normals is None


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("names", [("u", "v"), ("texture_u", "texture_v"), ("texture_s", "texture_t")])
def test_vertex_texcoord_names(tmp_path, fmt, names):
    vertex = [("float", "x"), ("float", "y"), ("float", "z"), ("float", names[0]), ("float", names[1])]
    rows = [(0.0, 0.0, 0.0, 0.25, 0.5), (1.0, 0.0, 0.0, 0.75, 0.5), (0.0, 1.0, 0.0, 0.25, 1.0)]
    mesh = load(write_ply(tmp_path / "v.ply", fmt, [("vertex", vertex, rows), ("face", FACE[:1], [([0, 1, 2],)])]))
    np.testing.assert_array_equal(mesh.texcoords, [r[3:] for r in rows])


def test_float_colours_are_kept(tmp_path):
    vertex = [("float", "x"), ("float", "y"), ("float", "z"), ("float", "red"), ("float", "green"), ("float", "blue")]
    rows = [(0.0, 0.0, 0.0, 0.25, 0.5, 1.0), (1.0, 0.0, 0.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 1.0, 1.0, 1.0)]
    mesh = load(write_ply(tmp_path / "c.ply", "binary_little_endian",
                          [("vertex", vertex, rows), ("face", FACE[:1], [([0, 1, 2],)])]))
    np.testing.assert_array_equal(mesh.colors, [r[3:] for r in rows])


@pytest.mark.parametrize("fmt", FORMATS[1:])
def test_binary_runs_of_mixed_face_sizes(tmp_path, fmt):
    rng = np.random.default_rng(7)
    sizes = np.concatenate([np.full(3000, 4), rng.integers(3, 7, 500), np.full(2000, 3), [5, 4, 3] * 100])
    faces = [(list(rng.integers(0, 5, s)),) for s in sizes]
    mesh = load(write_ply(tmp_path / "runs.ply", fmt,
                          [("vertex", VERTEX[:3], [r[:3] for r in VERTEX_ROWS]), ("face", FACE[:1], faces)]))
    assert mesh.face_sizes.tolist() == sizes.tolist()
    assert mesh.corner_vertex.tolist() == [i for (f,) in faces for i in f]


@pytest.mark.parametrize("fmt", FORMATS)
def test_vertices_without_faces_is_a_point_cloud_and_skipped(tmp_path, fmt):
    """No face element, or one with no rows: a point cloud, not a mesh (skipped as ``no-mesh``)."""
    points = [("vertex", VERTEX[:3], [r[:3] for r in VERTEX_ROWS])]
    for elements in (points, points + [("face", FACE, [])]):
        with pytest.raises(SkippedFile) as skip:
            load(write_ply(tmp_path / "points.ply", fmt, elements))
        assert skip.value.reason == "no-mesh"


def test_fixture():
    square = load(DATA / "square.ply")
    assert square.face_sizes.tolist() == [4, 3] and square.face_line.tolist() == [16, 17]


@pytest.mark.parametrize("fmt", FORMATS)
def test_tristrips_read_as_triangles(tmp_path, fmt):
    """Stanford-style ``tristrips`` (igea, elephant): -1 restarts a strip; checked against trimesh's converter."""
    from trimesh.util import triangle_strips_to_faces

    rng = np.random.default_rng(7)
    rows = [tuple(rng.uniform(-1, 1, 3).tolist()) for _ in range(12)]
    items = [0, 1, 2, 3, 4, 5, -1, 6, 7, 8, 8, 9, 10, 11, -1, 2, 3, 6]
    strips_element = ("tristrips", [("list", "int", "int", "vertex_indices")], [(items,), ([5, 6, 7, 1],)])
    path = write_ply(tmp_path / "strips.ply", fmt, [("vertex", VERTEX[:3], rows), strips_element])
    mesh = load(path)
    mesh.validate()
    pieces = [[0, 1, 2, 3, 4, 5], [6, 7, 8, 8, 9, 10, 11], [2, 3, 6], [5, 6, 7, 1]]
    expected = triangle_strips_to_faces([np.array(p) for p in pieces])
    expected = expected[(expected[:, 0] != expected[:, 1]) & (expected[:, 1] != expected[:, 2])
                        & (expected[:, 0] != expected[:, 2])]
    got = mesh.corner_vertex.reshape(-1, 3)
    assert mesh.counts() == {"faces": len(expected), "quads": 0, "triangles": len(expected), "ngons": 0}

    def oriented(triangles):  # each triangle rotated to start at its smallest corner: winding kept
        return sorted(tuple(np.roll(t, -int(np.argmin(t))).tolist()) for t in triangles)

    assert oriented(got) == oriented(expected)
    assert any("triangle strip" in note and "2 degenerate" in note for note in mesh.notes)
    if fmt == "ascii":
        assert sorted(set(mesh.face_line.tolist())) == [23, 24]  # 10 header lines, 12 vertices


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("bad", [2.5, float("nan"), float("inf"), 1e30])
def test_tristrip_indices_that_are_not_whole_are_refused_at_their_line(tmp_path, fmt, bad):
    """As in face lists: a float strip item must be a whole number, not truncated to a vertex (2.5 -> 2)."""
    rows = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 1.0, 0.0), (2.0, 1.0, 0.0)]
    strips = ("tristrips", [("list", "int", "float", "vertex_indices")], [([0.0, 1.0, 2.0, 3.0],),
                                                                         ([1.0, 3.0, bad, 4.0],)])
    path = write_ply(tmp_path / "strips.ply", fmt, [("vertex", VERTEX[:3], rows), strips])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning from casting NaN to an index
        with pytest.raises(MeshError, match="vertex index out of range") as info:
            load(path)
    assert info.value.line == (17 if fmt == "ascii" else 0)  # 10 header lines, 5 vertices, the second strip


@pytest.mark.parametrize("fmt", FORMATS)
def test_nan_colour_is_a_note_not_an_error(tmp_path, fmt):
    vertex = [("float", "x"), ("float", "y"), ("float", "z"), ("float", "red"), ("float", "green"), ("float", "blue")]
    rows = [(0.0, 0.0, 0.0, 1.0, 0.0, 0.0), (1.0, 0.0, 0.0, float("nan"), 0.0, 0.0), (1.0, 1.0, 0.0, 0.0, 1.0, 0.0)]
    path = write_ply(tmp_path / "nan_colour.ply", fmt, [("vertex", vertex, rows), ("face", FACE[:1], [([0, 1, 2],)])])
    mesh = load(path)
    assert mesh.colors is None and len(mesh.notes) == 1 and "NaN" in mesh.notes[0]
    np.testing.assert_array_equal(mesh.positions, np.array(rows)[:, :3])
    assert mesh.counts()["triangles"] == 1


@pytest.mark.parametrize("count", [300_000_000, 4_000_000_000])
def test_binary_header_lying_about_its_size_is_refused_before_allocating(tmp_path, count):
    """A 177-byte file claiming 3e8 vertices (or 4e9) is a clean error, not gigabytes of arrays."""
    import tracemalloc

    path = write_ply(tmp_path / "liar.ply", "binary_little_endian",
                     [("vertex", VERTEX[:3], [(0.0, 0.0, 0.0)] * 3), ("face", FACE[:1], [([0, 1, 2],)])])
    path.write_bytes(path.read_bytes().replace(b"element vertex 3", f"element vertex {count}".encode()))
    tracemalloc.start()
    try:
        with pytest.raises(MeshError) as caught:
            load(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert "truncated" in caught.value.reason and str(count) in caught.value.reason
    assert peak < 10_000_000
