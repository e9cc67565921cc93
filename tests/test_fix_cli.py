"""``affinity fix`` as a user runs it: outputs, the OBJ kept byte for byte, the shared meshes fixed, exit codes."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest
from helpers.cli import SQUARE, TRAPEZOID, run, write
from helpers.corpus import shared_mesh_paths
from helpers.fixing import local_copy

from affinity.fix import FixSettings, apply_fix, plan_fix, refine_mesh
from affinity.loaders import load

SCORED = ("Q101", "Q102", "Q103")
LEVELS = ("info", "warning", "error")
#: The shared meshes with a Q101-Q103 finding (all but none of them: each OBJ has one).
SHARED = shared_mesh_paths("*.obj") + shared_mesh_paths("textured/*.obj")


def check_json(path) -> dict:
    result = run("check", "--format", "json", "--isolated", str(path))
    assert result.returncode in (0, 1), result.stderr
    return json.loads(result.stdout)


def findings_of(path) -> list[dict]:
    """Every finding of ``affinity check --format json PATH``."""
    return check_json(path)["findings"]


def test_dry_run_json_lists_refined_and_left_faces_and_writes_nothing(tmp_path):
    path = write(tmp_path, "trapezoid.obj", TRAPEZOID)
    result = run("fix", "--dry-run", "--format", "json", str(path))
    assert result.returncode == 1  # the trapezoid needs n = 23 > 8: left, needing a re-UV
    entry = json.loads(result.stdout)["files"][0]
    assert entry["refine"] == []
    assert entry["left"] == [{"face": 0, "reason": "over-cap", "line": 9, "where": f"{path}:9:1"}]
    result = run("fix", "--dry-run", "--format", "json", "--max-refine", "24", str(path))
    assert result.returncode == 0
    entry = json.loads(result.stdout)["files"][0]
    assert [(r["face"], r["n"]) for r in entry["refine"]] == [(0, 23)]
    assert entry["refine"][0]["before"] > 100 > 0.5 > entry["refine"][0]["after"]
    assert entry["faces_added"] == 23 * 23 - 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["trapezoid.obj"]


def test_text_dry_run_names_each_face_with_its_line(tmp_path):
    path = write(tmp_path, "trapezoid.obj", TRAPEZOID)
    result = run("fix", "--dry-run", str(path))
    assert f"{path}:9:1: left (over-cap): needs more than --max-refine: re-UV it [face 0]" in result.stdout
    result = run("fix", "--dry-run", "--max-refine", "24", str(path))
    assert f"{path}:9:1: would refine n=23: Q101 175.7 -> 0.4737 texels [face 0]" in result.stdout
    assert "+528 faces" in result.stdout


def test_default_output_is_beside_the_input_which_stays_as_it_was(tmp_path):
    path = write(tmp_path, "trapezoid.obj", TRAPEZOID)
    result = run("fix", "--max-refine", "24", str(path))
    assert result.returncode == 0, result.stderr
    assert path.read_text() == TRAPEZOID
    fixed = tmp_path / "trapezoid.fixed.obj"
    assert fixed.read_text().startswith(TRAPEZOID.rsplit("f ", 1)[0])
    assert load(fixed).n_faces == 23 * 23
    assert findings_of(fixed) == []


def test_in_place_replaces_the_input_and_o_names_the_output(tmp_path):
    path = write(tmp_path, "t.obj", TRAPEZOID)
    out = tmp_path / "elsewhere.obj"
    assert run("fix", "--max-refine", "24", "-o", str(out), str(path)).returncode == 0
    assert path.read_text() == TRAPEZOID and load(out).n_faces == 529
    assert run("fix", "--max-refine", "24", "--in-place", str(path)).returncode == 0
    assert path.read_bytes() == out.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["elsewhere.obj", "t.obj"]


def test_a_bad_file_gets_one_line_and_the_others_are_still_fixed(tmp_path):
    bad = write(tmp_path, "bad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n")
    good = write(tmp_path, "good.obj", TRAPEZOID)
    result = run("fix", "--max-refine", "24", str(bad), str(good))
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and result.stderr.startswith(f"{bad}:4: Q901 unreadable:")
    assert "Traceback" not in result.stderr
    assert (tmp_path / "good.fixed.obj").exists() and not (tmp_path / "bad.fixed.obj").exists()


def test_an_existing_output_survives_a_failed_fix_and_the_input_is_refused_as_output(tmp_path):
    bad = write(tmp_path, "bad.obj", "v 0 0 nan\n")
    out = write(tmp_path, "out.obj", "keep me\n")
    result = run("fix", "-o", str(out), str(bad))
    assert result.returncode == 2 and out.read_text() == "keep me\n" and "Traceback" not in result.stderr
    good = write(tmp_path, "good.obj", TRAPEZOID)
    result = run("fix", "-o", str(good), str(good))
    assert result.returncode == 2 and "--in-place" in result.stderr and good.read_text() == TRAPEZOID


def test_nothing_flagged_writes_nothing_and_exits_0(tmp_path):
    path = write(tmp_path, "square.obj", SQUARE)
    result = run("fix", str(path))
    assert result.returncode == 0 and "nothing to write" in result.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["square.obj"]


def test_ply_and_off_are_written_whole_and_read_back_as_the_fixed_mesh(tmp_path):
    obj = write(tmp_path, "t.obj", TRAPEZOID)
    expected = load(obj)
    expected = apply_fix(expected, plan_fix(expected, FixSettings(max_refine=24)))
    ply = write(tmp_path, "t.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                "property float z\nproperty float s\nproperty float t\nelement face 1\n"
                "property list uchar int vertex_indices\nend_header\n"
                "-1 0 0 0 0\n1 0 0 1 0\n0.5 1 0 1 1\n-0.5 1 0 0 1\n4 0 1 2 3\n")
    off = write(tmp_path, "t.off", "STOFF\n4 1 0\n-1 0 0 0 0\n1 0 0 1 0\n0.5 1 0 1 1\n-0.5 1 0 0 1\n4 0 1 2 3\n")
    for path in (ply, off):
        assert run("fix", "--max-refine", "24", str(path)).returncode == 0
        fixed = load(tmp_path / f"t.fixed{path.suffix}")
        assert fixed.n_faces == expected.n_faces
        np.testing.assert_allclose(fixed.positions[fixed.corner_vertex], expected.positions[expected.corner_vertex],
                                   atol=1e-6)
        np.testing.assert_allclose(fixed.texcoords[fixed.corner_texcoord],
                                   expected.texcoords[expected.corner_texcoord], atol=1e-6)
        assert findings_of(tmp_path / f"t.fixed{path.suffix}") == []


@pytest.fixture
def textured_spot(shared_meshes, tmp_path):
    """The textured Spot copied with its material and texture, so the fix sits beside them."""
    for name in ("spot_control_mesh_textured.obj", "spot.mtl", "spot_texture.png"):
        shutil.copy(shared_meshes / "textured" / name, tmp_path / name)
    return tmp_path / "spot_control_mesh_textured.obj"


def test_untouched_obj_lines_are_byte_identical_and_in_order(textured_spot):
    source = textured_spot.read_bytes()
    plan = json.loads(run("fix", "--dry-run", "--format", "json", str(textured_spot)).stdout)["files"][0]
    assert run("fix", str(textured_spot)).returncode == 1  # some quads are left
    output = (textured_spot.parent / "spot_control_mesh_textured.fixed.obj").read_bytes()
    mesh = load(textured_spot)
    replaced = sorted({r["face"] for r in plan["refine"]} | set(plan["transitions"]))
    dropped = set(mesh.face_line[replaced].tolist())
    lines = source.splitlines(keepends=True)
    assert all(lines[n - 1].startswith(b"f ") for n in dropped)
    kept = b"".join(line for number, line in enumerate(lines, 1) if number not in dropped)
    assert output.startswith(kept)
    appended = output[len(kept):].decode()
    assert appended.startswith("# affinity fix: ")
    assert "usemtl spot" in appended  # the material in force at the replaced faces, restated
    # no index of an existing line moved: the faces kept read the same corners
    fixed = load(textured_spot.parent / "spot_control_mesh_textured.fixed.obj")
    kept_faces = np.setdiff1d(np.arange(mesh.n_faces), replaced)
    for name in ("corner_vertex", "corner_texcoord"):
        before = [getattr(mesh, name)[mesh.face_start[f]:mesh.face_start[f + 1]].tolist() for f in kept_faces]
        after = [getattr(fixed, name)[fixed.face_start[f]:fixed.face_start[f + 1]].tolist()
                 for f in range(len(kept_faces))]
        assert before == after
    assert (fixed.face_material[len(kept_faces):] == mesh.face_material[replaced[0]]).all()


def test_appended_faces_restate_their_groups(shared_meshes, tmp_path):
    path = shutil.copy(shared_meshes / "makehuman_base_hm08.obj", tmp_path / "human.obj")
    mesh = load(path)
    refined = refine_mesh(mesh, plan_fix(mesh))
    assert run("fix", str(path)).returncode in (0, 1)
    fixed = load(tmp_path / "human.fixed.obj")
    assert fixed.n_faces == refined.mesh.n_faces
    names_after = np.array(fixed.group_names, dtype=object)[fixed.face_group]
    names_source = np.array(mesh.group_names, dtype=object)[mesh.face_group[refined.source]]
    assert (names_after == names_source).all()


@pytest.mark.parametrize("path", SHARED or [pytest.param(None, marks=pytest.mark.skip("no shared meshes"))],
                         ids=[p.name for p in SHARED] or ["absent"])
def test_after_fix_check_finds_no_scored_finding_but_on_left_quads_and_the_rest_unchanged(path, tmp_path):
    local = local_copy(path, tmp_path)
    result = run("fix", "--dry-run", "--format", "json", str(local))
    plan = json.loads(result.stdout)["files"][0]
    left = {r["face"] for r in plan["left"]}
    assert run("fix", str(local)).returncode == (1 if left else 0)
    out = local.with_name(local.stem + ".fixed.obj")
    before, after = findings_of(local), findings_of(out)
    mesh = load(local)
    refined = refine_mesh(mesh, plan_fix(mesh))
    replaced = {r["face"] for r in plan["refine"]} | set(plan["transitions"])
    kept = [f for f in range(mesh.n_faces) if f not in replaced]
    assert refined.source[: len(kept)].tolist() == kept
    at_level = [f for f in after if f["code"] in SCORED and LEVELS.index(f["level"]) >= LEVELS.index("warning")]
    assert {int(refined.source[f["face"]]) for f in at_level} <= left
    unchanged = {(f["code"], kept[f["face"]], round(f["value"], 9), f["level"]) for f in after
                 if f["code"] not in SCORED and f["face"] < len(kept) and f["code"][:2] != "Q9"}
    expected = {(f["code"], f["face"], round(f["value"], 9), f["level"]) for f in before
                if f["code"] not in SCORED and f["face"] not in replaced and f["code"][:2] != "Q9"}
    assert unchanged == expected


def test_a_neighbour_without_uv_is_re_cut_and_written_without_uv(tmp_path):
    # the trapezoid, and a square below it sharing its bottom edge, written without texture coordinates
    text = TRAPEZOID + "v -1 -1 0\nv 1 -1 0\nf 5 6 2 1\n"
    path = write(tmp_path, "mixed.obj", text)
    assert run("fix", "--max-refine", "24", str(path)).returncode == 0
    fixed_text = (tmp_path / "mixed.fixed.obj").read_text()
    fixed = load(tmp_path / "mixed.fixed.obj")
    # 23 x 23 pieces with uv; the square cut into quads closing to the 23 segments of the shared edge, without uv
    square = fixed.n_faces - 23 * 23
    assert (fixed.face_sizes == 4).all() and square > 1
    assert (fixed.corner_texcoord[fixed.face_start[-square]:] == -1).all()
    assert all("/" not in line for line in fixed_text.splitlines()[-square:])
    assert findings_of(tmp_path / "mixed.fixed.obj") == []


def test_usage_errors_are_one_line_and_exit_2(tmp_path):
    path = write(tmp_path, "t.obj", TRAPEZOID)
    other = write(tmp_path, "u.obj", TRAPEZOID)
    stage = write(tmp_path, "s.usda", "#usda 1.0\n")
    for args, says in ((["-o", str(tmp_path / "t.ply"), str(path)], "its own format"),
                       (["--max-refine", "99", str(path)], "not a level from 1 to 63"),
                       (["--in-place", str(stage)], "--in-place"),
                       (["-o", str(tmp_path / "x.obj"), str(path), str(other)], "one output"),
                       ([str(tmp_path / "missing.obj")], "no such file")):
        result = run("fix", *args)
        assert result.returncode == 2 and says in result.stderr and "Traceback" not in result.stderr, args
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.usda", "t.obj", "u.obj"]


def test_a_directory_is_walked_and_earlier_fixes_in_it_are_not_inputs(tmp_path):
    write(tmp_path, "t.obj", TRAPEZOID)
    (tmp_path / "sub").mkdir()
    write(tmp_path / "sub", "s.obj", SQUARE)
    assert run("fix", "--max-refine", "24", str(tmp_path)).returncode == 0
    assert (tmp_path / "t.fixed.obj").exists() and not (tmp_path / "sub" / "s.fixed.obj").exists()
    again = run("fix", "--max-refine", "24", "--dry-run", str(tmp_path))
    assert "t.fixed.obj" not in again.stdout and "t.obj: would refine 1 quads" in again.stdout


def test_a_silenced_face_is_not_fixed_and_nonplanar_quads_only_on_request(tmp_path):
    silenced = write(tmp_path, "silenced.obj",
                     TRAPEZOID.replace("f 1/1 2/2 3/3 4/4", "f 1/1 2/2 3/3 4/4  # affinity: ignore[Q101]"))
    result = run("fix", "--max-refine", "24", "--format", "json", "--dry-run", str(silenced))
    assert result.returncode == 0 and json.loads(result.stdout)["files"][0]["refine"] == []
    # a square folded 60 degrees along its diagonal 0-2 (Q202), whose uv is not affine to it (Q101, 36 texels)
    folded = write(tmp_path, "folded.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.25 0.75 0.6124\n"
                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0.1 0.9\nf 1/1 2/2 3/3 4/4\n")
    left = json.loads(run("fix", "--dry-run", "--format", "json", "--max-refine", "16", str(folded)).stdout)
    assert left["files"][0]["left"][0]["reason"] == "nonplanar"
    refined = json.loads(run("fix", "--dry-run", "--format", "json", "--max-refine", "16", "--refine-nonplanar",
                             str(folded)).stdout)
    assert [r["face"] for r in refined["files"][0]["refine"]] == [0]


def test_windows_line_ends_are_kept_and_used_for_the_new_lines(tmp_path):
    path = write(tmp_path, "t.obj", TRAPEZOID.replace("\n", "\r\n").encode())
    assert run("fix", "--max-refine", "24", str(path)).returncode == 0
    output = (tmp_path / "t.fixed.obj").read_bytes()
    assert output.startswith(TRAPEZOID.replace("\n", "\r\n").rsplit("f ", 1)[0].encode())
    assert output.count(b"\n") == output.count(b"\r\n") and load(tmp_path / "t.fixed.obj").n_faces == 529


def test_dry_run_reports_the_faces_a_grid_with_one_flagged_quad_gains(tmp_path):
    """A 5 x 5 grid whose middle quad carries a uv trapezoid of its own: --dry-run's faces_added is what
    the fix adds, all quads, within the budget, and its bytes estimate within a factor 2 of the file's growth."""
    lines = [f"v {x} {y} 0" for y in range(6) for x in range(6)] + [f"vt {x / 5} {y / 5}" for y in range(6)
                                                                     for x in range(6)]
    lines += ["vt 0.40 0.40", "vt 0.60 0.40", "vt 0.57 0.6", "vt 0.43 0.6"]
    for j in range(5):
        for i in range(5):
            v = [j * 6 + i + 1, j * 6 + i + 2, (j + 1) * 6 + i + 2, (j + 1) * 6 + i + 1]
            t = [37, 38, 39, 40] if (i, j) == (2, 2) else v
            lines.append("f " + " ".join(f"{a}/{b}" for a, b in zip(v, t)))
    path = write(tmp_path, "grid.obj", "\n".join(lines) + "\n")
    entry = json.loads(run("fix", "--dry-run", "--format", "json", str(path)).stdout)["files"][0]
    assert [r["face"] for r in entry["refine"]] == [12] and entry["left"] == []
    n = entry["refine"][0]["n"]
    assert entry["transitions"] == [7, 11, 13, 17]
    assert n % 2 == 1 and n * n - 1 < entry["faces_added"] <= entry["faces_added_bound"]
    assert run("fix", str(path)).returncode == 0
    fixed = load(tmp_path / "grid.fixed.obj")
    assert fixed.n_faces == 25 + entry["faces_added"] and (fixed.face_sizes == 4).all()
    growth = (tmp_path / "grid.fixed.obj").stat().st_size - path.stat().st_size
    assert growth / 2 <= entry["bytes_added"] <= 2 * growth
