"""affinity.fix keeps quads (issue 54): the cuts are quads only and conform, left faces are never cut, the
result is re-checked, the output has a budget, and a textured quad is refined by its shift, in its own texture.

Independent truths: the parameter square's geometry (areas, convexity, every inner edge shared by two cells,
every border edge a segment of the face's edge); the input mesh's edge map (edges by the number of faces
sharing them, their lengths) against the output's; the check's own JSON of the written file; the input's bytes.
"""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
from helpers.cli import TRAPEZOID, run, write
from helpers.corpus import shared_mesh_paths
from helpers.fixing import edge_map_agrees, grid_with_one_flagged_quad, local_copy

from affinity.fix import FixSettings, plan_fix, refine_mesh
from affinity.fix.patterns import SQUARE, quad_pattern
from affinity.loaders import load

SCORED = ("Q101", "Q102", "Q103")
LEVELS = ("info", "warning", "error")
ODD = (1, 3, 5, 9, 27)
SHARED = shared_mesh_paths("*.obj") + shared_mesh_paths("textured/*.obj")


def ring_points(counts: tuple[int, ...]) -> np.ndarray:
    """(M, 2) the face's border points in the parameter square: corner i, then k / counts[i] along edge i."""
    rows = []
    for i, c in enumerate(counts):
        rows += [SQUARE[i] + k / c * (SQUARE[(i + 1) % 4] - SQUARE[i]) for k in range(c)]
    return np.array(rows)


@pytest.mark.parametrize("level", ODD[:5])
def test_every_cut_of_odd_counts_is_convex_quads_tiling_the_square_and_meeting_its_border(level):
    for counts in itertools.product(ODD, repeat=4):
        pattern = quad_pattern(counts, level)
        M = sum(counts)
        points = np.concatenate([ring_points(counts), pattern.inner])
        cells = np.array(pattern.polygons)
        assert cells.shape[1] == 4, counts
        c = points[cells]  # (Q, 4, 2)
        edge = np.roll(c, -1, axis=1) - c
        turn = edge[:, :, 0] * np.roll(edge, -1, axis=1)[:, :, 1] - edge[:, :, 1] * np.roll(edge, -1, axis=1)[:, :, 0]
        assert (turn > 1e-12).all(), counts  # every corner turns left: convex, the face's orientation
        area = 0.5 * (c[:, :, 0] * np.roll(c, -1, axis=1)[:, :, 1] - np.roll(c, -1, axis=1)[:, :, 0] * c[:, :, 1]).sum()
        assert area == pytest.approx(1.0, abs=1e-12), counts  # no overlap, no gap
        directed = {(int(a), int(b)) for cell in cells for a, b in zip(cell, np.roll(cell, -1))}
        assert len(directed) == 4 * len(cells)
        border = {(a, b) for a, b in directed if (b, a) not in directed}
        assert border == {(k, (k + 1) % M) for k in range(M)}, counts  # no T-junction on the face's edges


def test_a_grid_with_one_flagged_quad_costs_its_grid_and_one_3_to_1_cell_per_neighbour():
    from affinity.settings import Settings

    mesh, _ = grid_with_one_flagged_quad()
    plan = plan_fix(mesh, FixSettings(lint=Settings(texture_size=256)))  # a quarter of the texels: n = 3
    assert plan.refine_n.tolist() == [3]
    fixed = refine_mesh(mesh, plan).mesh
    # Schneiders' 3-to-1 template: a neighbour whose edge carries 3 segments becomes 4 quads
    assert fixed.n_faces - mesh.n_faces == plan.faces_added == (9 - 1) + 4 * (4 - 1)


def test_a_quad_refined_beside_a_left_quad_leaves_it_untouched_and_closes_to_it():
    """Two flagged quads side by side; one needs more than the cap (left over-cap): its face is kept, with
    its edge unsplit, and the refined one closes to that edge with quads."""
    positions = np.array([[x, y, 0.0] for y in (0, 1) for x in range(3)])
    faces = np.array([[0, 1, 4, 3], [1, 2, 5, 4]])
    from affinity.mesh import mesh_from_polygons

    mesh = mesh_from_polygons("pair", positions, faces, texcoords=positions[:, :2] / 3)
    trapezoids = [[[0.0, 0], [0.3, 0], [0.2, 0.3], [0.1, 0.3]], [[0.5, 0], [0.75, 0], [0.74, 0.25], [0.51, 0.25]]]
    mesh.texcoords = np.vstack([mesh.texcoords, *trapezoids])
    mesh.corner_texcoord = len(positions) + np.arange(8)
    plan = plan_fix(mesh)
    assert plan.left_faces.tolist() == [0] and plan.left_reasons.tolist() == ["over-cap"]
    assert plan.refine_faces.tolist() == [1]
    refined = refine_mesh(mesh, plan)
    fixed = refined.mesh
    assert (fixed.face_sizes == 4).all()
    kept = np.flatnonzero(refined.source == 0)
    assert len(kept) == 1 and not refined.added[kept[0]]
    assert fixed.corner_vertex[fixed.face_start[kept[0]]:fixed.face_start[kept[0] + 1]].tolist() == [0, 1, 4, 3]
    # the shared edge x = 1 has no new point
    assert not np.isclose(fixed.positions[len(positions):, 0], 1.0).any()
    edge_map_agrees(mesh, fixed)


@pytest.mark.parametrize("path", SHARED or [pytest.param(None, marks=pytest.mark.skip("no shared meshes"))],
                         ids=[p.name for p in SHARED] or ["absent"])
def test_shared_meshes_get_no_new_triangle_or_ngon_no_t_junction_and_left_faces_kept(path):
    mesh = load(path)
    plan = plan_fix(mesh)
    refined = refine_mesh(mesh, plan)
    fixed = refined.mesh
    fixed.validate()
    # a face that is not a quad is a face of the input kept, or the one face replacing an input face that is not
    new_sizes = fixed.face_sizes[refined.added]
    sources = refined.source[refined.added]
    assert (new_sizes[mesh.face_sizes[sources] == 4] == 4).all()
    not_quads = sources[mesh.face_sizes[sources] != 4]
    assert len(not_quads) == len(np.unique(not_quads))
    assert np.count_nonzero(fixed.face_sizes != 4) == np.count_nonzero(mesh.face_sizes != 4)
    # no T-junction; the boundary's edges (shared by one face) keep their length and lie on input boundary edges;
    # a closed mesh stays closed (both: the edges shared by one face)
    edge_map_agrees(mesh, fixed)
    # a left face is in the output as it was, never cut by a neighbour's refinement
    kept = ~refined.added
    assert np.isin(plan.left_faces[np.isin(plan.left_reasons, ["still-flagged"], invert=True)],
                   refined.source[kept]).all()
    assert not np.isin(plan.left_faces, refined.replaced).any() or set(
        plan.left_reasons[np.isin(plan.left_faces, refined.replaced)]) == {"still-flagged"}


def test_the_shared_car_is_all_quads_after_the_fix(shared_meshes):
    mesh = load(shared_meshes / "osd_catmark_car.obj")
    assert (mesh.face_sizes == 4).all()
    fixed = refine_mesh(mesh, plan := plan_fix(mesh)).mesh
    assert len(plan.refine_faces) > 300 and (fixed.face_sizes == 4).all()


#: Faces the triangulating fix left on the shared meshes at its defaults (docs/fix.md's table at commit
#: e2bb43c, a regression value): the quad-only fix leaves no more.
LEFT_BEFORE = {"gen_uv_sphere_64x32.obj": 128, "makehuman_base_hm08.obj": 10, "osd_catmark_bishop.obj": 452,
               "osd_catmark_car.obj": 1094, "spot_control_mesh.obj": 42}


@pytest.mark.parametrize("name", sorted(LEFT_BEFORE))
def test_the_fix_leaves_no_more_faces_than_the_triangulating_fix_did(shared_meshes, name):
    plan = plan_fix(load(shared_meshes / name))
    assert len(plan.left_faces) <= LEFT_BEFORE[name]
    assert len(plan.refine_faces) > 0


@pytest.mark.parametrize("path", SHARED or [pytest.param(None, marks=pytest.mark.skip("no shared meshes"))],
                         ids=[p.name for p in SHARED] or ["absent"])
def test_fix_then_check_flags_only_left_faces_whose_lines_are_byte_identical(path, tmp_path):
    local = local_copy(path, tmp_path)
    result = run("fix", "--format", "json", str(local))
    entry = json.loads(result.stdout)["files"][0]
    assert result.returncode == (1 if entry["left"] else 0), result.stderr
    out = local.with_name(local.stem + ".fixed.obj")
    checked = json.loads(run("check", "--format", "json", "--isolated", str(out)).stdout)["findings"]
    source_lines = local.read_bytes().splitlines()
    out_lines = out.read_bytes().splitlines()
    mesh = load(local)
    replaced = {r["face"] for r in entry["refine"]} | set(entry["transitions"])
    kept = [f for f in range(mesh.n_faces) if f not in replaced]  # the output's first faces, in file order
    left = {r["face"] for r in entry["left"]}
    assert left <= set(kept)
    at_level = [f for f in checked if f["code"] in SCORED and LEVELS.index(f["level"]) >= LEVELS.index("warning")]
    for finding in at_level:  # every scored finding is on a left face, its line byte for byte the input's
        assert finding["face"] < len(kept) and kept[finding["face"]] in left, finding
        assert out_lines[finding["line"] - 1] == source_lines[mesh.face_line[kept[finding["face"]]] - 1]


def test_a_wrong_prediction_is_left_still_flagged_with_exit_1_and_its_line_kept(tmp_path, monkeypatch, capsys):
    """The plan is told every piece is clean (n = 3 for a trapezoid that needs 23): the re-check finds it
    still flagged, the fix leaves it as it was, says ``still-flagged`` and exits 1; the check agrees."""
    import affinity.fix.plan as plan_module
    from affinity.cli import main

    monkeypatch.setattr(plan_module, "piece_scores", lambda mesh, faces, n, settings, code: np.zeros(len(faces)))
    path = write(tmp_path, "t.obj", TRAPEZOID + "v -1 -1 0\nv 1 -1 0\nvt 0 -1\nvt 1 -1\nf 5/5 6/6 2/2 1/1\n")
    assert main(["fix", "--format", "json", "--isolated", str(path)]) == 1
    entry = json.loads(capsys.readouterr().out)["files"][0]
    assert [(r["face"], r["reason"]) for r in entry["left"]] == [(0, "still-flagged")]
    assert entry["refine"] == []
    assert not (tmp_path / "t.fixed.obj").exists()  # nothing left to refine: nothing written
    assert main(["check", "--isolated", str(path)]) == 1


def test_over_budget_refines_the_worst_first(shared_meshes):
    mesh = load(shared_meshes / "gen_vase_revolution.obj")
    full = plan_fix(mesh)
    budget = full.faces_added // 3
    plan = plan_fix(mesh, FixSettings(max_faces_added=budget))
    assert plan.faces_added <= budget
    over = plan.left_faces[plan.left_reasons == "over-budget"]
    assert len(over) and len(plan.refine_faces)
    # the badness of every refined quad (value over threshold, from the full plan's readings) is at least that
    # of every quad left over budget
    badness = dict(zip(full.refine_faces.tolist(), (full.before / 0.5).tolist()))
    assert min(badness[f] for f in plan.refine_faces.tolist()) >= max(badness[f] for f in over.tolist())


def test_a_result_adding_another_rules_finding_is_written_only_when_allowed(tmp_path, monkeypatch, capsys):
    """The re-check is told the result adds a Q203 on a face the fix cannot leave (one it does not cut): the
    result is refused (exit 1, nothing written, the face named) unless --allow-new-findings (written; exit 1
    still, the result having the finding)."""
    import affinity.fix.loop as loop
    from affinity.cli import main

    real = loop.verify

    def adding(mesh, plan, fix, baseline):
        flagged, _ = real(mesh, plan, fix, baseline)
        return flagged, [{"code": "Q203", "face": 1}]

    monkeypatch.setattr(loop, "verify", adding)
    path = write(tmp_path, "t.obj", TRAPEZOID + "v 3 0 0\nv 4 0 0\nv 4 1 0\nv 3 1 0\nf 5/1 6/2 7/3 8/4\n")
    assert main(["fix", "--max-refine", "24", "--format", "json", "--isolated", str(path)]) == 1
    entry = json.loads(capsys.readouterr().out)["files"][0]
    assert [(d["code"], d["face"]) for d in entry["new_findings"]] == [("Q203", 1)] and entry["refine"]
    assert "output" not in entry and not (tmp_path / "t.fixed.obj").exists()
    assert main(["fix", "--max-refine", "24", "--allow-new-findings", "--isolated", str(path)]) == 1
    assert (tmp_path / "t.fixed.obj").exists() and "adds Q203" in capsys.readouterr().out
