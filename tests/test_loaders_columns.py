"""The OBJ reader's column path (lines laid out alike, :mod:`affinity.loaders.columns`).

Generated files hold only ``v``/``vt``/``vn``/``f`` lines (and blank and comment lines), so that chunks are read
as groups of lines laid out alike: numbers of random signs, digit counts (up to the
15 that a float64 holds exactly, longer than a word) and separators, faces of one
form. The mesh must equal what Python's own ``float`` and ``int`` make of the text,
and the token reader's mesh, bit for bit, at every chunk size; lines the column path
must not take (exponents, 16 digits, index 0, other statements) go to the token reader.
"""

import random

import numpy as np
import pytest

from affinity.errors import MeshError
from affinity.loaders.obj import alike, load_obj

CHUNK_SIZES = (None, 4096, 300, 61)
FORMS = {"v": (0,), "v/vt": (0, 1), "v//vn": (0, 2), "v/vt/vn": (0, 1, 2)}


def _number(rng: random.Random) -> str:
    whole = rng.choice([0, 1, 2, 3, 6, 9])
    fraction = rng.choice([0, 1, 4, 6, 8, 13 - whole if whole < 13 else 0])
    text = "".join(rng.choice("0123456789") for _ in range(max(whole, 1)))
    if fraction:
        text += "." + "".join(rng.choice("0123456789") for _ in range(fraction))
    return rng.choice(["", "", "-", "+"]) + text


def _corner(index: tuple, form: str) -> str:
    v, t, n = index
    return {"v": f"{v}", "v/vt": f"{v}/{t}", "v//vn": f"{v}//{n}", "v/vt/vn": f"{v}/{t}/{n}"}[form]


def generated(seed: int) -> tuple[str, dict]:
    """An OBJ text of runs of lines laid out alike (and some not), and its mesh in plain Python."""
    rng = random.Random(seed)
    counts = {"v": rng.randint(3, 400), "vt": rng.randint(3, 300), "vn": rng.randint(3, 300)}
    widths = {"v": 3, "vt": rng.choice([1, 2, 3]), "vn": 3}
    form = rng.choice(list(FORMS))
    size = rng.choice([3, 4, 4, 5])
    gap = rng.choice([" ", " ", "  ", "\t"])
    end = rng.choice(["\n", "\n", "\r\n", " \n"])
    lines, truth = [], {k: [] for k in counts}
    for kind, count in counts.items():
        for _ in range(count):
            numbers = [_number(rng) for _ in range(widths[kind])]
            truth[kind].append([float(x) for x in numbers])
            lines.append(gap.join([kind, *numbers]) + end)
        if rng.random() < 0.3:
            lines.append(end)  # a blank line
        if rng.random() < 0.3:
            lines.append(f"# {kind} 1/2 done" + end)  # a comment line
    faces, face_line = [], []
    for _ in range(rng.randint(1, 500)):
        base = rng.choice([1, 9, 99, 999, 9999, 99999, 9999999]) % counts["v"] + 1
        corners = [((base + k) % counts["v"] + 1, (base + 2 * k) % counts["vt"] + 1, (base + k) % counts["vn"] + 1)
                   for k in range(size)]
        faces.append(corners)
        lines.append(gap.join(["f", *(_corner(c, form) for c in corners)]) + end)
        face_line.append(len(lines))
    truth["faces"], truth["face_line"], truth["slots"], truth["size"] = faces, face_line, FORMS[form], size
    return "".join(lines), truth


def _assert_matches(mesh, truth: dict) -> None:
    assert np.array_equal(mesh.positions, np.array(truth["v"]))
    assert np.array_equal(np.signbit(mesh.positions), np.signbit(np.array(truth["v"])))  # -0.0 stays -0.0
    corners = np.array(truth["faces"]) - 1  # (F, size, 3)
    assert np.array_equal(mesh.face_start, np.arange(len(corners) + 1) * truth["size"])
    assert np.array_equal(mesh.face_line, truth["face_line"])
    assert np.array_equal(mesh.corner_vertex, corners[:, :, 0].reshape(-1))
    if 1 in truth["slots"]:
        uv = np.zeros((len(truth["vt"]), 2))
        rows = np.array(truth["vt"])
        uv[:, : min(2, rows.shape[1])] = rows[:, :2]
        assert np.array_equal(mesh.texcoords, uv)
        assert np.array_equal(mesh.corner_texcoord, corners[:, :, 1].reshape(-1))
    if 2 in truth["slots"]:
        assert np.array_equal(mesh.normals, np.array(truth["vn"]))
        assert np.array_equal(mesh.corner_normal, corners[:, :, 2].reshape(-1))


def _token_reader_only(monkeypatch) -> None:
    monkeypatch.setattr(alike, "alike_part", lambda chunk: None)


@pytest.mark.parametrize("seed", range(12))
def test_column_path_matches_python_and_the_token_reader(tmp_path, monkeypatch, seed):
    text, truth = generated(seed)
    path = tmp_path / "alike.obj"
    path.write_bytes(text.encode())
    taken = []
    real = alike.alike_part

    def spied(chunk):  # on the worker threads: return this chunk's part, not whichever was appended last
        part = real(chunk)
        taken.append(part)
        return part

    monkeypatch.setattr(alike, "alike_part", spied)
    meshes = [load_obj(path, chunk_bytes=size) for size in CHUNK_SIZES]
    assert any(part is not None for part in taken), "the column path was never taken"
    _token_reader_only(monkeypatch)
    meshes.append(load_obj(path))
    for mesh in meshes:
        _assert_matches(mesh, truth)


@pytest.mark.parametrize("line, error", [
    ("v 1e3 0 0", None),  # an exponent: the token reader's
    ("v 1.234567890123456 0 0", None),  # 16 digits: the token reader rounds
    ("v 1 2 3 0.5 0.5 0.5", None),  # a colour
    ("g part", None),
    ("v 1 2 3 # a trailing comment", None),
    ("f 0 1 2", "bad index '0'"),
    ("f 1 2", "face with 2 corners"),
    ("v 1 2 nan", "not a finite number"),
])
def test_lines_the_column_path_leaves_to_the_token_reader(tmp_path, line, error):
    """A line unlike the others in a run of lines laid out alike: read (or refused, naming
    its line) exactly as the token reader does."""
    lines = ["v 1.0 2.0 3.0"] * 40 + [line] + ["v 1.5 2.5 3.5"] * 40 + ["f 1 2 3"] * 10
    path = tmp_path / "odd.obj"
    path.write_text("\n".join(lines) + "\n")
    if error is None:
        mesh = load_obj(path)
        assert len(mesh.positions) == 80 + line.startswith("v")
        assert mesh.face_line[0] == 82
        return
    with pytest.raises(MeshError) as raised:
        load_obj(path)
    assert raised.value.line == 41 and error in raised.value.reason


@pytest.mark.parametrize("runs", [("same", "other", "same"), ("other", "same"), ("same", "plain", "same")])
def test_slots_that_repeat_the_vertex_index(tmp_path, runs):
    """``f 7/7/7`` corners (attributes stored per vertex) give the texcoord and normal slots the
    vertex slot's array; a later run of corners that differ (or lack the slots) parts them,
    at every chunk size, and the indices are those of the text."""
    count = 50
    lines = [f"v {k}.5 {k % 7}.25 -{k % 3}.0" for k in range(count)]
    lines += [f"vt 0.{k:02d} 0.5" for k in range(count)] + [f"vn 0 0 {k + 1}.0" for k in range(count)]
    truth = []  # (v, vt, vn) per corner, 0-based, -1 where absent
    for run in runs:
        for face in range(30):
            corners = [((face + k) % count, (face + (run != "same") * (3 * k + 1) + k) % count) for k in range(4)]
            if run == "plain":
                lines.append("f " + " ".join(f"{v + 1}" for v, _ in corners))
                truth += [(v, -1, -1) for v, _ in corners]
            else:
                lines.append("f " + " ".join(f"{v + 1}/{t + 1}/{t + 1}" for v, t in corners))
                truth += [(v, t, t) for v, t in corners]
    path = tmp_path / "twins.obj"
    path.write_text("\n".join(lines) + "\n")
    expected = np.array(truth).T
    for size in CHUNK_SIZES:
        mesh = load_obj(path, chunk_bytes=size)
        for index, slot in zip((mesh.corner_vertex, mesh.corner_texcoord, mesh.corner_normal), expected):
            assert np.array_equal(index, slot), size
    whole = load_obj(path, chunk_bytes=1 << 20)
    if set(runs) == {"same"}:
        assert whole.corner_texcoord is whole.corner_vertex
