"""Every kind of bad input is a MeshError naming the right line (or a SkippedFile)."""

import struct
from pathlib import Path

import numpy as np
import pytest
from helpers.bad_obj import BAD_FIFTH_LINE, BAD_OTHER_LINE, SQUARE

from affinity.errors import MeshError, SkippedFile
from affinity.loaders import load

PLY_HEADER = ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 1\nproperty list uchar int vertex_indices\nend_header\n")  # 9 lines


def error_of(tmp_path, content, name="mesh.obj") -> MeshError:
    path = tmp_path / name
    path.write_bytes(content.encode() if isinstance(content, str) else content)
    with pytest.raises(MeshError) as caught:
        load(path)
    assert caught.value.path == str(path)
    return caught.value


@pytest.mark.parametrize("body, line, words", [
    *((SQUARE + statement + "\n", 5, words) for words, statements in BAD_FIFTH_LINE.items()
      for statement in statements),
    *BAD_OTHER_LINE,
])
def test_obj_errors_name_the_line(tmp_path, body, line, words):
    error = error_of(tmp_path, body)
    assert error.line == line
    assert words in error.reason


def test_truncated_obj_mid_number(tmp_path):
    full = SQUARE + "vt 0 0\nvt 1 0\nf 1/1 2/2 3/1 4/2\nf 2/1 3/2 4/1\n"
    cut = full[: full.rindex("4/1") + 2]  # "... 4/" : the last corner lost its vt
    assert error_of(tmp_path, cut).line == 8
    assert error_of(tmp_path, SQUARE + "f 1 2 3 44").line == 5  # refers to a vertex that never came


@pytest.mark.parametrize("content", ["", "   \n\n\t\n", "# only a comment\n# and another\n", "o nothing\n"])
def test_obj_without_content_is_an_empty_file(tmp_path, content):
    error = error_of(tmp_path, content)
    assert error.line == 0 and "empty" in error.reason


def test_binary_junk_names_its_line(tmp_path):
    error = error_of(tmp_path, SQUARE.encode() + b"f 1 2 3\n\x00\x01\x02binary\xff\n")
    assert error.line == 6 and "binary" in error.reason


def test_nul_byte_in_a_vertex_line(tmp_path):
    assert error_of(tmp_path, b"v 0 0 0\nv 1 0\x000\n").line == 2


def test_non_utf8_in_numbers(tmp_path):
    """Names may be any 8-bit text (test_loaders_obj), numbers may not."""
    assert error_of(tmp_path, b"v 0 0 0\nv 1 \xe9 0\n").line == 2
    assert error_of(tmp_path, SQUARE.encode() + b"f 1 2 \xe9\n").line == 5


def test_errors_point_into_later_chunks(tmp_path, monkeypatch):
    from affinity.loaders import text

    monkeypatch.setattr(text, "CHUNK_BYTES", 32)
    body = "".join(f"v {k} 0 0\n" for k in range(100)) + "f 1 2 3\n" * 20 + "f 1 2 300\n"
    assert error_of(tmp_path, body).line == 121


def test_lfs_pointer_is_skipped(tmp_path):
    path = tmp_path / "big.obj"
    path.write_text("version https://git-lfs.github.com/spec/v1\noid sha256:abc\nsize 123\n")
    with pytest.raises(SkippedFile) as caught:
        load(path)
    assert caught.value.reason == "lfs-pointer"


@pytest.mark.parametrize("name", ["mesh.stl", "mesh", "mesh.obj.bak"])
def test_unknown_extension(tmp_path, name):
    error = error_of(tmp_path, SQUARE, name=name)
    assert error.line == 0 and "format" in error.reason


def test_missing_file_and_directory(tmp_path):
    for path in (tmp_path / "absent.obj", tmp_path / "folder.ply"):
        if path.suffix == ".ply":
            path.mkdir()
        with pytest.raises(MeshError) as caught:
            load(path)
        assert caught.value.line == 0


@pytest.mark.parametrize("name", ["empty.obj", "empty.ply", "empty.off", "EMPTY.OBJ"])
def test_zero_byte_file(tmp_path, name):
    error = error_of(tmp_path, b"", name=name)
    assert error.line == 0 and "empty" in error.reason


@pytest.mark.parametrize(
    "content, line",
    [
        ("COFF\n3 1 0\n0 0 0 255 0 0\n1 0 0 0 255 0\n", 4),  # truncated: the last line read
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", 6),
        ("OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", 4),
        ("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", 4),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", 6),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n1 1 1\n", 7),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", 6),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", 6),
        ("OFX\n3 1 0\n", 1),
        ("OFF\n3 x 0\n", 2),
        ("# nothing but a comment\n", 1),
    ],
)
def test_off_errors(tmp_path, content, line):
    assert error_of(tmp_path, content, name="mesh.off").line == line


@pytest.mark.parametrize(
    "content, line",
    [
        ("plx\n", 1),
        ("ply\nformat ascii 2.0 x\nend_header\n", 2),
        ("ply\nformat ascii 1.0\nelement vertex\nend_header\n", 3),
        ("ply\nformat ascii 1.0\nproperty float x\nend_header\n", 3),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n", 4),
        ("ply\nformat ascii 1.0\nelement face 1\nproperty list float int vertex_indices\nend_header\n", 4),
        ("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", 5),
        ("ply\nelement vertex 1\nproperty float x\nend_header\n", 4),
        (PLY_HEADER + "0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n", 13),
        (PLY_HEADER + "0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", 11),
        (PLY_HEADER + "0 0 0\n1 0 0\n0 1 0\n", 12),
        (PLY_HEADER + "0 0 0\n1 0\n0 1 0\n3 0 1 2\n", 11),
        (PLY_HEADER + "0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", 13),
        (PLY_HEADER + "0 0 0\n1 0 0\n0 1 0\n9 0 1 2\n", 13),
        (PLY_HEADER + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", 13),
    ],
)
def test_ascii_ply_errors(tmp_path, content, line):
    assert error_of(tmp_path, content, name="mesh.ply").line == line


def binary_ply(vertices: int, faces: bytes) -> bytes:
    header = PLY_HEADER.replace("ascii", "binary_little_endian").replace("vertex 3", f"vertex {vertices}")
    return header.encode() + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + faces


@pytest.mark.parametrize(
    "faces, words",
    [
        (struct.pack("<B3i", 3, 0, 1, 7), "out of range"),
        (struct.pack("<B2i", 3, 0, 1), "truncated"),
        (struct.pack("<B", 3), "truncated"),
        (b"", "truncated"),
        (struct.pack("<B3i", 3, 0, 1, 2) + b"junk", "after the last element"),
        (struct.pack("<B3i", 3, 0, 1, -1), "out of range"),
    ],
)
def test_binary_ply_errors_have_line_zero(tmp_path, faces, words):
    error = error_of(tmp_path, binary_ply(3, faces), name="mesh.ply")
    assert error.line == 0 and words in error.reason


def test_binary_ply_nan_and_count_mismatch(tmp_path):
    content = binary_ply(3, struct.pack("<B3i", 3, 0, 1, 2)).replace(struct.pack("<f", 1),
                                                                     struct.pack("<f", float("nan")), 1)
    assert "finite" in error_of(tmp_path, content, name="mesh.ply").reason
    # a vertex count one too high shifts the face data: still a clean error, line 0
    assert error_of(tmp_path, binary_ply(4, struct.pack("<B3i", 3, 0, 1, 2)), name="mesh.ply").line == 0


@pytest.mark.parametrize("name", ["textured_quads.obj", "square.off", "square.ply", "binary.ply"])
def test_mutated_files_raise_only_mesh_errors(tmp_path, name):
    """Seeded random byte edits of valid files: a Mesh with finite positions and corners in range, a skip
    (a PLY whose faces were cut is a point cloud), or a MeshError of one line naming the file and a line
    within it, never another exception."""
    data = Path(__file__).parent / "data" / "loaders"
    original = binary_ply(3, struct.pack("<B3i", 3, 0, 1, 2)) if name == "binary.ply" else (data / name).read_bytes()
    rng = np.random.default_rng(sum(map(ord, name)))
    alphabet = list(b" \t\n\r/\\#-+.0123456789eEnaif\x00\xff")
    path = tmp_path / name
    outcomes = {"mesh": 0, "error": 0, "skip": 0}
    for _ in range(300):
        mutated = bytearray(original)
        for _ in range(rng.integers(1, 4)):
            at = int(rng.integers(len(mutated) + 1))
            edit = rng.integers(4)
            if edit == 0 and at < len(mutated):
                mutated[at] = int(rng.choice(alphabet))
            elif edit == 1:
                mutated[at:at] = bytes([int(rng.choice(alphabet))])
            elif edit == 2:
                del mutated[at : at + int(rng.integers(1, 5))]
            else:
                del mutated[at:]
        path.write_bytes(bytes(mutated))
        try:
            mesh = load(path)
        except MeshError as err:
            outcomes["error"] += 1
            assert err.path == str(path) and err.reason.strip(), str(err)
            assert "\n" not in err.reason and "Traceback" not in err.reason, err.reason
            # At most one past the last line: a truncated PLY header names the line its end_header was due on.
            assert 0 <= err.line <= mutated.count(b"\n") + 2, str(err)
            continue
        except SkippedFile:
            outcomes["skip"] += 1
            continue
        outcomes["mesh"] += 1
        assert np.isfinite(mesh.positions).all()
        assert ((mesh.corner_vertex >= 0) & (mesh.corner_vertex < len(mesh.positions))).all()
    assert outcomes["error"] > 0 and outcomes["mesh"] > 0, outcomes  # both kinds of edit were made
