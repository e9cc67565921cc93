"""Bad input costs no more than good input (issue 45), and only regular files are read (issue 47).

Small versions of the benchmark's cases (``benchmarks/bench_pathological.py`` measures the
big ones): each bad file gets one clear Q901 line naming the offset, exit 2, no traceback and
no partial output; FIFOs and devices as mesh, material library, texture and USD layer are
refused by name before any read, in check, render and report. Every command runs in a
subprocess with a timeout, so a read that blocks fails the test instead of hanging it.
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.cli import SQUARE, TRAPEZOID, write

from affinity.errors import MeshError, SkippedFile
from affinity.loaders import load, text
from affinity.loaders.regular import RefusedFile, open_regular, read_regular

pytestmark = pytest.mark.slow  # each command in a process of its own with a time limit, on big and blocking files

requires_usd = pytest.mark.skipif(importlib.util.find_spec("pxr") is None, reason="needs the usd extra (usd-core)")
requires_dev_zero = pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")

#: Seconds a command gets: a FIFO read blocks forever, a device read runs for minutes.
PROMPTLY = 60

TEXTURED = "mtllib {mtl}\nusemtl wood\n" + SQUARE
PLY_HEADER = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n"
QUAD_USDA = ('#usda 1.0\ndef Mesh "quad" {\n    int[] faceVertexCounts = [4]\n'
             '    int[] faceVertexIndices = [0, 1, 2, 3]\n'
             '    point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0)]\n}\n')


def run(*args: str, cache=None) -> subprocess.CompletedProcess:
    """``affinity ARGS`` in a subprocess; with ``cache`` (a folder) the result cache is on there."""
    env = os.environ if cache is None else {**os.environ, "AFFINITY_CACHE_DIR": str(cache)}
    return subprocess.run([sys.executable, "-m", "affinity.cli", *args], capture_output=True, text=True,
                          env=env, timeout=PROMPTLY)


def special(tmp_path, name: str, kind: str):
    """A FIFO (no writer ever) or a link to /dev/zero named ``name``."""
    path = tmp_path / name
    if kind == "fifo":
        os.mkfifo(path)
    else:
        if not os.path.exists("/dev/zero"):
            pytest.skip("needs /dev/zero")
        os.symlink("/dev/zero", path)
    return path


WORDS = {"fifo": "is a FIFO (named pipe), not a regular file", "device": "is a character device, not a regular file"}


# -- the helper ------------------------------------------------------------------------------------


def test_a_fifo_without_a_writer_is_refused_at_once(tmp_path):
    fifo = special(tmp_path, "pipe.mtl", "fifo")
    with pytest.raises(RefusedFile) as caught:
        open_regular(fifo)
    assert caught.value.strerror == "is a FIFO (named pipe), not a regular file: not read"
    assert caught.value.filename == str(fifo)


@requires_dev_zero
def test_a_device_is_refused_before_any_read():
    with pytest.raises(RefusedFile, match="is a character device"):
        read_regular("/dev/zero", budget=1 << 20)


def test_a_directory_is_refused(tmp_path):
    with pytest.raises(RefusedFile, match="is a directory"):
        open_regular(tmp_path)


def test_a_side_file_over_its_budget_is_refused_and_one_within_it_read_whole(tmp_path):
    path = write(tmp_path, "big.mtl", b"x" * 1001)
    with pytest.raises(RefusedFile, match=r"is 1001 bytes, over the 1000 bytes budget"):
        read_regular(path, budget=1000)
    assert read_regular(path, budget=1001) == b"x" * 1001
    assert read_regular(path) == b"x" * 1001


# -- FIFOs and devices where the tools open files --------------------------------------------------


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_check_refuses_a_special_mesh_with_one_line_and_exit_2(tmp_path, kind):
    mesh = special(tmp_path, "mesh.obj", kind)
    result = run("check", "--no-cache", str(mesh))
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"{mesh}:0: Q901 unreadable: {WORDS[kind]}: not read"]


@pytest.mark.parametrize("kind", ["fifo", "device"])
@pytest.mark.parametrize("role", ["mtllib", "map_Kd"])
def test_check_names_a_special_side_file_in_q902_and_checks_the_mesh(tmp_path, kind, role):
    if role == "mtllib":
        special(tmp_path, "lib.mtl", kind)
    else:
        write(tmp_path, "lib.mtl", "newmtl wood\nmap_Kd wood.png\n")
        special(tmp_path, "wood.png", kind)
    mesh = write(tmp_path, "mesh.obj", TEXTURED.format(mtl="lib.mtl"))
    for cached in (False, True):
        result = run("check", "--format", "json", *([] if cached else ["--no-cache"]), str(mesh),
                     cache=tmp_path / "cache")
        assert result.returncode == 0, result.stderr
        [finding] = json.loads(result.stdout)["findings"]
        assert finding["code"] == "Q902"
        named = "mtllib lib.mtl" if role == "mtllib" else "map_Kd wood.png (in lib.mtl)"
        assert f"{named} {WORDS[kind]}: not read" in finding["message"]


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_render_refuses_a_special_mesh_and_writes_nothing(tmp_path, kind):
    mesh = special(tmp_path, "mesh.obj", kind)
    result = run("render", str(mesh), "-o", str(tmp_path / "out.png"), "--size", "32x24")
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"affinity render: error: {mesh}:0: {WORDS[kind]}: not read"]
    assert not (tmp_path / "out.png").exists()


@pytest.mark.parametrize("kind", ["fifo", "device"])
@pytest.mark.parametrize("role", ["mtllib", "map_Kd"])
def test_render_draws_with_the_checker_for_a_special_side_file_and_says_why(tmp_path, kind, role):
    if role == "mtllib":
        side, named = special(tmp_path, "lib.mtl", kind), "mtllib "
    else:
        write(tmp_path, "lib.mtl", "newmtl wood\nmap_Kd wood.png\n")
        side, named = special(tmp_path, "wood.png", kind), ""
    mesh = write(tmp_path, "mesh.obj", TEXTURED.format(mtl="lib.mtl"))
    result = run("render", str(mesh), "-o", str(tmp_path / "out.png"), "--size", "32x24", "-q")
    assert result.returncode == 0, result.stderr
    assert result.stderr.splitlines() == [
        f"affinity render: warning: {side}: {named}{WORDS[kind]}: not read; using the checker texture"]
    assert (tmp_path / "out.png").read_bytes().startswith(b"\x89PNG")


def test_report_refuses_a_fifo_mesh_and_a_fifo_texture_and_reports_the_rest(tmp_path):
    fifo_mesh = special(tmp_path, "pipe.obj", "fifo")
    write(tmp_path, "lib.mtl", "newmtl wood\nmap_Kd wood.png\n")
    texture = special(tmp_path, "wood.png", "fifo")
    textured = write(tmp_path, "textured.obj", TEXTURED.format(mtl="lib.mtl"))
    page = tmp_path / "report.html"
    result = run("report", str(fifo_mesh), str(textured), "-o", str(page), "--size", "64x48")
    assert result.returncode == 2
    assert f"{fifo_mesh}:0: Q901 unreadable: {WORDS['fifo']}: not read" in result.stderr.splitlines()
    assert "Traceback" not in result.stderr
    html = page.read_text()
    assert "textured.obj" in html and f"wood.png: {WORDS['fifo']}: not read; using the checker texture" in html
    assert texture.is_fifo()


@requires_usd
@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_a_special_usd_sublayer_is_refused_by_name(tmp_path, kind):
    layer = special(tmp_path, "layer.usda", kind)
    header = "#usda 1.0\n(\n    subLayers = [@./layer.usda@]\n)\n"
    stage = write(tmp_path, "stage.usda", QUAD_USDA.replace("#usda 1.0\n", header))
    result = run("check", "--no-cache", str(stage))
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"{stage}:0: Q901 unreadable: the layer {layer} {WORDS[kind]}: not read"]


# -- bytes that cannot be text: read no further than the first chunk -------------------------------


class Endless:
    """A file object whose bytes never end (``pattern`` over and over), counting what was read."""

    def __init__(self, pattern: bytes, prefix: bytes = b""):
        self.prefix, self.pattern, self.read = prefix, pattern, 0

    def tell(self) -> int:
        return 0

    def readinto(self, into) -> int:
        head = self.prefix[self.read :]
        at = max(self.read - len(self.prefix), 0) % len(self.pattern)  # where in the pattern the rest starts
        rest = self.pattern * (len(into) // len(self.pattern) + 2)
        into[:] = (head + rest[at:])[: len(into)]
        self.read += len(into)
        return len(into)


def test_zero_bytes_without_end_stop_the_read_in_the_first_chunk():
    endless = Endless(b"\0", prefix=b"v 0 0 0\nv 1 0 0\n")
    chunks = text.read_chunks(endless, "zeros.obj", size=1 << 16)
    first = next(chunks)  # the whole lines before the zeros come first
    assert bytes(first.buf[text.PAD : text.PAD + 16]) == b"v 0 0 0\nv 1 0 0\n"
    with pytest.raises(MeshError) as caught:
        next(chunks)
    assert caught.value.line == 3
    assert caught.value.reason == ("binary data (byte 0x00) at offset 16: not a text mesh"
                                   " (a zero-filled or damaged file?)")
    assert endless.read == 1 << 16


def test_text_without_line_breaks_stops_the_read_in_the_first_long_line():
    endless = Endless(b"abc ")
    with pytest.raises(MeshError, match=r"bytes with no line break and no statement at offset 0: not a text mesh"):
        list(text.read_chunks(endless, "prose.obj", size=1 << 12, long_line=None))
    assert endless.read < 2 * text.LONG_LINE_BYTES


def test_a_face_without_end_stops_at_the_line_cap(monkeypatch):
    monkeypatch.setattr(text, "MAX_LINE_BYTES", 1 << 20)
    endless = Endless(b" 1 2 3", prefix=b"f")
    from affinity.loaders.obj.scan import LONG_LINE

    with pytest.raises(MeshError, match=r"a line longer than 1 MiB at offset 0: not a text mesh"):
        list(text.read_chunks(endless, "face.obj", size=1 << 12, long_line=LONG_LINE))
    assert endless.read < 4 << 20  # the blocks double: the line cap and at most as much again


@pytest.mark.parametrize("name, content, line, reason", [
    ("zeros.obj", b"\0" * 300_000, 1,
     "binary data (byte 0x00) at offset 0: not a text mesh (a zero-filled or damaged file?)"),
    ("cut.obj", SQUARE.encode() + b"\0" * 300_000, 10,
     f"binary data (byte 0x00) at offset {len(SQUARE)}: not a text mesh (a zero-filled or damaged file?)"),
    ("line.obj", b"x" * 300_000, 1, "300,000 bytes with no line break and no statement at offset 0: not a text mesh"),
    ("prose.obj", b"Dear reader, this is a letter.\n" * 10, 1,
     "no OBJ statement in the 309 bytes at offset 0: not an OBJ file"),
    ("zeros.off", b"OFF\n4 1 0\n" + b"\0" * 300_000, 3,
     "binary data (byte 0x00) at offset 10: not a text mesh (a zero-filled or damaged file?)"),
    ("zeros.ply", PLY_HEADER + b"\0" * 300_000, 6,
     f"binary data (byte 0x00) at offset {len(PLY_HEADER)}: not a text mesh (a zero-filled or damaged file?)"),
])
def test_bytes_that_cannot_be_the_format_are_one_q901_naming_the_offset(tmp_path, name, content, line, reason):
    mesh = write(tmp_path, name, content)
    with pytest.raises(MeshError) as caught:
        load(mesh)
    assert (caught.value.line, caught.value.reason) == (line, reason)
    result = run("check", "--no-cache", str(mesh))
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"{mesh}:{line}: Q901 unreadable: {reason}"]


@pytest.mark.parametrize("content", [b"\0" * 300_000, os.urandom(300_000), b"x" * 300_000],
                         ids=["zeros", "random", "no-line-break"])
def test_a_bad_mesh_leaves_no_output_and_destroys_none(tmp_path, content):
    mesh = write(tmp_path, "bad.obj", content)
    kept = write(tmp_path, "kept.png", b"an earlier render")
    for command in ("render", "report"):
        fresh = tmp_path / f"fresh.{command}"
        result = run(command, str(mesh), "-o", str(fresh), "--size", "32x24")
        assert result.returncode == 2 and "Traceback" not in result.stderr
        assert "not a text mesh" in result.stderr
        assert not fresh.exists() or command == "report"  # a report names the unreadable file
        if command == "report":
            assert "not a text mesh" in fresh.read_text()
    result = run("render", str(mesh), "-o", str(kept), "--size", "32x24")
    assert result.returncode == 2 and kept.read_bytes() == b"an earlier render"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.obj", "fresh.report", "kept.png"]


def test_a_bad_file_in_a_folder_is_one_q901_and_the_others_are_checked(tmp_path):
    write(tmp_path, "zeros.obj", b"\0" * 3_000_000)
    write(tmp_path, "clean.obj", SQUARE)
    trapezoid = "v -1 0 0\nv 1 0 0\nv 0.5 1 0\nv -0.5 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n"
    write(tmp_path, "trapezoid.obj", trapezoid)
    result = run("check", "--no-cache", "--format", "json", str(tmp_path))
    assert result.returncode == 2
    assert [line for line in result.stderr.splitlines() if "Q901" in line] == [
        f"{tmp_path / 'zeros.obj'}:1: Q901 unreadable: binary data (byte 0x00) at offset 0: not a text mesh"
        " (a zero-filled or damaged file?)"]
    document = json.loads(result.stdout)
    assert [(os.path.basename(f["path"]), f["code"]) for f in document["findings"]] == [("trapezoid.obj", "Q101")]


@pytest.mark.parametrize("cached", [False, True], ids=["no-cache", "cache"])
def test_a_fifo_or_device_in_a_folder_is_one_q901_naming_it_and_the_others_are_checked(tmp_path, cached):
    fifo = special(tmp_path, "pipe.obj", "fifo")
    device = special(tmp_path, "zero.ply", "device")
    special(tmp_path, "notes.txt", "fifo")  # not a mesh name: the walk passes it by, as it does a regular .txt
    write(tmp_path, "trapezoid.obj", TRAPEZOID)
    result = run("check", "--format", "json", *([] if cached else ["--no-cache"]), str(tmp_path),
                 cache=tmp_path.parent / "cache" if cached else None)
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"{fifo}:0: Q901 unreadable: {WORDS['fifo']}: not read",
                                          f"{device}:0: Q901 unreadable: {WORDS['device']}: not read"]
    document = json.loads(result.stdout)
    assert sorted(os.path.basename(entry["path"]) for entry in document["files"]) == [
        "pipe.obj", "trapezoid.obj", "zero.ply"]
    assert [(os.path.basename(f["path"]), f["code"]) for f in document["findings"]] == [("trapezoid.obj", "Q101")]


# -- odd but valid: read as they are ---------------------------------------------------------------


def test_a_face_of_100000_corners_is_one_ngon(tmp_path):
    corners = 100_000
    vertices = "".join(f"v {k % 317} {k // 317} 0\n" for k in range(corners))
    mesh = load(write(tmp_path, "fan.obj", vertices + "f " + " ".join(str(k + 1) for k in range(corners)) + "\n"))
    assert mesh.counts() == {"faces": 1, "quads": 0, "triangles": 0, "ngons": 1}
    assert mesh.face_start.tolist() == [0, corners]
    assert mesh.corner_vertex.tolist() == list(range(corners))


def test_one_triangle_faces_and_a_face_of_one_repeated_index(tmp_path):
    faces = 10_000
    body = "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 3\n" * faces + "f 2 2 2 2\n"
    result = run("check", "--no-cache", "--format", "json", str(write(tmp_path, "many.obj", body)))
    document = json.loads(result.stdout)
    [entry] = document["files"]
    assert (entry["faces"], entry["triangles"], entry["quads"]) == (faces + 1, faces, 1)
    assert [(f["code"], f["face"], f["line"]) for f in document["findings"]] == [("Q201", faces, faces + 4)]


@pytest.mark.parametrize("names", [127, 128, 40_000])
def test_group_and_material_tables_hold_every_name_past_a_narrow_type(tmp_path, names):
    # The tables take the narrowest integer type that holds the names (int8 to 127, then int16, int32):
    # face k is in group k and material k, and a face before any usemtl has none (-1).
    faces = "".join(f"g part{k}\nusemtl m{k}\nf 1 2 3\n" for k in range(names))
    mesh = load(write(tmp_path, "named.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n" + faces))
    assert mesh.group_names == ["", *(f"part{k}" for k in range(names))]
    assert mesh.material_names == [f"m{k}" for k in range(names)]
    assert mesh.face_group.tolist() == list(range(names + 1))
    assert mesh.face_material.tolist() == list(range(-1, names))
    assert mesh.face_line.tolist() == [4, *range(7, 3 * names + 5, 3)]


@requires_usd
def test_usd_stage_of_many_empty_prims_is_skipped_and_nested_references_are_read(tmp_path):
    empty = write(tmp_path, "empty.usda", "#usda 1.0\n" + "".join(f'def Xform "p{k}" {{\n}}\n' for k in range(2000)))
    result = run("check", "--no-cache", "--format", "json", str(empty))
    assert result.returncode == 0 and json.loads(result.stdout)["files"][0]["skipped"] == "no-mesh"
    depth = 40
    write(tmp_path, f"level{depth}.usda", QUAD_USDA)
    for level in range(depth):
        reference = f"@./level{level + 1}.usda@</quad>"
        write(tmp_path, f"level{level}.usda", f'#usda 1.0\ndef "quad" (\n    references = {reference}\n)\n{{\n}}\n')
    result = run("check", "--no-cache", "--format", "json", str(tmp_path / "level0.usda"))
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["files"][0]["quads"] == 1


# -- a USD stage without a mesh: skipped from its layers' specs, not composed ---------------------

XFORM_USDA = '#usda 1.0\ndef Xform "top" {\n}\n'
VARIANT_USDA = """#usda 1.0
def Xform "top" (
    variants = {{
        string look = "{selected}"
    }}
    prepend variantSets = "look"
)
{{
    variantSet "look" = {{
        "bare" {{
            def Scope "nothing" {{
            }}
        }}
        "{meshed}" {{
            def Mesh "quad" {{
                int[] faceVertexCounts = [4]
                int[] faceVertexIndices = [0, 1, 2, 3]
                point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0)]
            }}
        }}
    }}
}}
"""


def usd_stages(folder) -> dict[str, object]:
    """Stages whose meshes hide behind every kind of composition arc, and stages without a mesh."""
    from pxr import Sdf

    write(folder, "quad.usda", QUAD_USDA)
    write(folder, "no-mesh.usda", '#usda 1.0\ndef Scope "lights" {\n    def Xform "key" {\n    }\n}\n')  # no look
    arcs = {"sublayer": '#usda 1.0\n(\n    subLayers = [@./{layer}@]\n)\n',
            "reference": '#usda 1.0\ndef Xform "top" (\n    references = @./{layer}@</quad>\n)\n{{\n}}\n',
            "payload": '#usda 1.0\ndef Xform "top" (\n    payload = @./{layer}@</quad>\n)\n{{\n}}\n'}
    stages = {f"{arc} to a mesh": write(folder, f"{arc}.usda", text.format(layer="quad.usda"))
              for arc, text in arcs.items()}
    stages |= {f"{arc} to no mesh": write(folder, f"{arc}-none.usda", text.format(layer="no-mesh.usda"))
               for arc, text in arcs.items()}
    stages["mesh in the selected variant"] = write(folder, "variant.usda", VARIANT_USDA.format(
        selected="meshed", meshed="meshed"))
    stages["mesh in a variant not selected"] = write(folder, "variant-off.usda", VARIANT_USDA.format(
        selected="bare", meshed="meshed"))
    write(folder, "variant-layer.usda", VARIANT_USDA.format(selected="meshed", meshed="meshed"))
    stages["reference to a variant's mesh"] = write(folder, "variant-reference.usda", arcs["reference"].format(
        layer="variant-layer.usda").replace("</quad>", "</top>"))
    stages["a mesh class inherited"] = write(folder, "inherits.usda", (
        '#usda 1.0\nclass Mesh "proto" {\n}\ndef "thing" (\n    inherits = </proto>\n)\n{\n'
        '    int[] faceVertexCounts = [4]\n    int[] faceVertexIndices = [0, 1, 2, 3]\n'
        '    point3f[] points = [(0,0,0), (1,0,0), (1,1,0), (0,1,0)]\n}\n'))
    stages["a type usd-core does not know"] = write(folder, "unknown.usda", '#usda 1.0\ndef Gizmo "g" {\n}\n')
    stages["a missing reference"] = write(folder, "missing.usda", arcs["reference"].format(layer="gone.usda"))
    stages["empty prims"] = write(folder, "empty.usda", "#usda 1.0\n" + "".join(
        f'def Xform "p{k}" {{\n}}\n' for k in range(200)))
    Sdf.Layer.FindOrOpen(str(stages["empty prims"])).Export(str(folder / "empty.usdc"))
    stages["empty prims, crate"] = folder / "empty.usdc"
    stages["the test fixture"] = Path(__file__).parent / "data" / "usd" / "scene.usda"
    return stages


USD_STAGES = ["sublayer to a mesh", "reference to a mesh", "payload to a mesh", "sublayer to no mesh",
              "reference to no mesh", "payload to no mesh", "mesh in the selected variant",
              "mesh in a variant not selected", "reference to a variant's mesh", "a mesh class inherited",
              "a type usd-core does not know", "a missing reference", "empty prims", "empty prims, crate",
              "the test fixture"]


@requires_usd
@pytest.mark.parametrize("case", USD_STAGES)
def test_a_stage_is_skipped_as_no_mesh_exactly_when_its_composition_has_no_drawn_mesh(tmp_path, case):
    from pxr import Usd, UsdGeom

    stage_path = usd_stages(tmp_path)[case]
    composed = Usd.Stage.Open(str(stage_path), Usd.Stage.LoadAll)  # the truth: usd-core composing it all
    drawn = [UsdGeom.Imageable(prim) for prim in Usd.PrimRange.Stage(composed, Usd.TraverseInstanceProxies())
             if prim.IsA(UsdGeom.Mesh)]
    meshes = [str(prim.GetPath()) for prim in drawn
              if prim.ComputeVisibility() != "invisible" and prim.ComputePurpose() not in ("guide", "proxy")]
    try:
        mesh = load(stage_path)
    except SkippedFile as skipped:
        assert skipped.reason == "no-mesh" and meshes == []
    else:
        assert mesh.group_names == meshes != []


@requires_usd
@pytest.mark.parametrize("case", ["empty prims", "empty prims, crate", "sublayer to no mesh",
                                  "reference to no mesh", "payload to no mesh"])
def test_a_stage_without_a_mesh_spec_is_skipped_without_composing_it(tmp_path, case, monkeypatch):
    from pxr import Usd

    stage_path = usd_stages(tmp_path)[case]

    def no_composing(*args, **kwargs):
        raise AssertionError("the stage was composed")

    monkeypatch.setattr(Usd.Stage, "Open", no_composing)
    with pytest.raises(SkippedFile, match=r"skipped \(no-mesh\)"):
        load(stage_path)


@pytest.mark.skipif(importlib.util.find_spec("pyvista") is None, reason="needs the view extra (pyvista)")
def test_a_big_face_reaches_vtk_as_its_fan_and_cell_f_stays_face_f():
    # VTK triangulates a polygon in quadratic time: the report's overview of one 100,000-corner face
    # took 103 s. A quad, a regular 1,000-gon of circumradius 1 and a triangle: the area is a closed form.
    import numpy as np

    from affinity.mesh import Mesh
    from affinity.view import VTK_POLYGON_CORNERS, polydata

    n = 1000
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    positions = np.vstack([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
                           np.c_[np.cos(angle), np.sin(angle), np.ones(n)], [[5, 5, 5], [6, 5, 5], [5, 6, 5]]])
    mesh = Mesh(path="three.obj", positions=positions, face_start=np.array([0, 4, 4 + n, 7 + n]),
                corner_vertex=np.arange(7 + n), face_line=np.array([1, 2, 3]))
    surface = polydata(mesh)
    assert n > VTK_POLYGON_CORNERS
    assert surface.n_cells == 3 + (n - 3)
    assert surface.area == pytest.approx(1 + n / 2 * np.sin(2 * np.pi / n) + 0.5, rel=1e-12)
    assert surface.get_cell(0).point_ids == [0, 1, 2, 3] and surface.get_cell(2).point_ids == [4 + n, 5 + n, 6 + n]


def test_a_mesh_over_the_render_budget_stops_with_one_line_and_the_report_says_so(tmp_path, monkeypatch):
    # 1,000 one-triangle faces against a budget of 999: the count is the file's, the cut-off the budget's.
    import affinity.draw.drawing as drawing
    from affinity.report.build import MeshInput, ReportOptions, collect_mesh
    from affinity.settings import Settings
    from render.raster import OverBudget

    path = write(tmp_path, "stack.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 3\n" * 1000)
    monkeypatch.setattr(drawing, "MAX_RENDER_QUADS", 999)
    reason = (f"{path}: 1,000 quads and triangles to draw, over the renderer's budget of 999 (about 1 KB of memory "
              "each): render a part of the mesh")
    with pytest.raises(OverBudget) as caught:
        drawing.render_mesh(str(path), drawing.RenderOptions(width=32, height=24))
    assert str(caught.value) == reason
    result = collect_mesh(MeshInput(path=str(path), label="stack"), Settings(), options=ReportOptions(size=(32, 24)))
    assert result.render_error == reason and not result.renders and result.overview is None
    monkeypatch.setattr(drawing, "MAX_RENDER_QUADS", 1000)
    assert len(drawing.render_mesh(str(path), drawing.RenderOptions(width=32, height=24)).faces) == 1000
