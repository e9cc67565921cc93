"""lint_mesh on small hand-made meshes, texture sizes from image headers, and the real corpus."""


import numpy as np
import pytest

import affinity.lint
from affinity.lint import lint_mesh, quad_uv_error
from affinity.loaders import load
from affinity.loaders.imagesize import image_size
from affinity.mesh import Mesh
from affinity.settings import Settings

SQUARE_UV = [[0, 0], [1, 0], [1, 1], [0, 1]]
TRAPEZOID = [[-1, 0, 0], [1, 0, 0], [0.5, 1, 0], [-0.5, 1, 0]]
#: The split's largest uv error on TRAPEZOID (side ratio r = 1/2) with SQUARE_UV: (1 - r) / (1 + sqrt r)^2
#: (``affinity.measures``; tests/test_measures_error.py checks it against sampling); 1/4 at the centre.
TRAPEZOID_ERROR = 0.5 / (1 + np.sqrt(0.5)) ** 2


def make_mesh(faces, positions, texcoords=None, normals=None, colors=None, path="test.obj", groups=None):
    """A Mesh whose corners index positions, texcoords and normals alike (face f, corner
    k -> vertex faces[f][k]); texcoord rows of NaN mark corners without one."""
    sizes = [len(f) for f in faces]
    corner_vertex = np.array([v for f in faces for v in f], dtype=np.int64)
    corner_texcoord = None
    if texcoords is not None:
        texcoords = np.asarray(texcoords, float)
        missing = np.isnan(texcoords).any(axis=1)
        corner_texcoord = np.where(missing[corner_vertex], -1, corner_vertex)
    return Mesh(
        path=path,
        positions=np.asarray(positions, float).reshape(-1, 3),
        face_start=np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
        corner_vertex=corner_vertex,
        face_line=np.arange(len(faces), dtype=np.int64) + 10,
        texcoords=texcoords,
        corner_texcoord=corner_texcoord,
        normals=None if normals is None else np.asarray(normals, float),
        corner_normal=None if normals is None else corner_vertex.copy(),
        colors=None if colors is None else np.asarray(colors, float),
        group_names=groups or [""],
        face_group=None if groups is None else np.arange(len(faces), dtype=np.int32) % len(groups),
    )


def quads_mesh(*quads, texcoords=None, **attributes):
    """One quad per (4, 3) corner list, with separate vertices."""
    positions = np.concatenate([np.asarray(q, float) for q in quads])
    faces = [list(range(4 * i, 4 * i + 4)) for i in range(len(quads))]
    if texcoords is not None:
        texcoords = np.concatenate([np.asarray(t, float) for t in texcoords])
    return make_mesh(faces, positions, texcoords, **attributes)


def found(mesh, **settings):
    """{code: (faces, values)} of lint_mesh."""
    return {h.code: (h.faces.tolist(), h.values) for h in lint_mesh(mesh, Settings(**settings))}


def test_trapezoid_is_flagged_in_texels_and_parallelogram_is_not():
    parallelogram = [[0, 0, 0], [2, 0, 0], [3, 1, 0], [1, 1, 0]]
    mesh = quads_mesh(parallelogram, TRAPEZOID, texcoords=[[[0, 0], [2, 0], [3, 1], [1, 1]], SQUARE_UV])
    hits = found(mesh)
    assert hits["Q101"][0] == [1]
    np.testing.assert_allclose(hits["Q101"][1], [TRAPEZOID_ERROR * 1024])
    np.testing.assert_allclose(found(mesh, texture_size=4)["Q101"][1], [TRAPEZOID_ERROR * 4])
    assert "Q101" not in found(mesh, texture_size=2)  # 0.34 texel, not above 0.5
    assert "Q101" not in found(mesh, thresholds={"Q101": 176.0})
    np.testing.assert_allclose(found(mesh, measure="centre")["Q101"][1], [0.125 * 1024])  # (1 - r) / 4


def test_barycentric_reading_uses_the_paper_tolerance():
    mesh = quads_mesh(TRAPEZOID, TRAPEZOID, texcoords=[SQUARE_UV, np.array(TRAPEZOID)[:, :2]])
    hits = lint_mesh(mesh, Settings(measure="barycentric", select=["Q101"]))
    assert [h.code for h in hits] == ["Q101"]
    assert hits[0].faces.tolist() == [0] and hits[0].threshold == 0.01
    np.testing.assert_allclose(hits[0].values, [np.sqrt(2)])


def test_face_indices_count_every_face_and_lines_and_groups_follow():
    positions = np.concatenate([[[5, 5, 0], [6, 5, 0], [5, 6, 0]], TRAPEZOID, TRAPEZOID])
    texcoords = np.concatenate([[[0, 0], [1, 0], [0, 1]], SQUARE_UV, SQUARE_UV])
    faces = [[0, 1, 2], [3, 4, 5, 6], [0, 1, 2, 7, 8], [7, 8, 9, 10]]
    mesh = make_mesh(faces, positions, texcoords, groups=["a", "b"])
    hits = lint_mesh(mesh, Settings(select=["Q101"]))
    assert hits[0].faces.tolist() == [1, 3]
    assert hits[0].lines.tolist() == [11, 13]
    assert hits[0].groups.tolist() == [1, 1]


def test_quads_with_a_corner_lacking_an_attribute_are_not_measured_for_it():
    texcoords = np.concatenate([SQUARE_UV, SQUARE_UV]).astype(float)
    texcoords[5] = np.nan
    mesh = quads_mesh(TRAPEZOID, TRAPEZOID, texcoords=[texcoords[:4], texcoords[4:]])
    assert found(mesh, select=["Q1", "Q3"])["Q101"][0] == [0]
    faces, m = quad_uv_error(mesh)
    assert faces.tolist() == [0, 1]
    np.testing.assert_allclose(m, [TRAPEZOID_ERROR, np.nan])


def test_map_kd_image_size_sets_the_texel_unit(tmp_path):
    pil = pytest.importorskip("PIL.Image")
    pil.new("RGB", (512, 256)).save(tmp_path / "wood.png")
    mesh = quads_mesh(TRAPEZOID, texcoords=[SQUARE_UV])
    mesh.material_names, mesh.material_textures = ["wood"], {"wood": str(tmp_path / "wood.png")}
    (hits,) = lint_mesh(mesh, Settings())
    np.testing.assert_allclose(hits.visible.shifts, [TRAPEZOID_ERROR * 512])  # a flat texture: C = 0
    np.testing.assert_allclose(hits.values, [0.0], atol=1e-3)
    assert hits.visible.units == ["1/255"] and hits.visible.roles == ["base colour"]
    np.testing.assert_allclose(found(mesh, texture_size=7)["Q101"][1], [0.0], atol=1e-3)
    mesh.material_textures = {"wood": str(tmp_path / "missing.png")}
    np.testing.assert_allclose(found(mesh, texture_size=100)["Q101"][1], [TRAPEZOID_ERROR * 100])


def test_colours_and_normals():
    square = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    blue, red, green, black = [0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 0, 0]
    bent = [np.sin(0.5), 0, np.cos(0.5)]
    mesh = quads_mesh(
        square, square,
        colors=[blue, red, green, black, blue, red, [1, 1, 0], [0, 1, 1]],
        normals=[[0, 0, 1], bent, [0, 0, 2], bent] + [[0, 0, 1]] * 4,  # unnormalized on purpose
    )
    hits = found(mesh)
    assert hits["Q102"][0] == [0]
    np.testing.assert_allclose(hits["Q102"][1], [255 * np.sqrt(3) / 4])
    assert hits["Q103"][0] == [0]
    np.testing.assert_allclose(hits["Q103"][1], [np.degrees(0.25)])


def test_shape_rules():
    square = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    pole = [[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, 1, 0]]
    warped = [[0, 0, 0], [1, 0, 0], [1, 1, 1], [0, 1, 0]]  # folds 60 degrees along 0-2, 54.7 along 1-3
    dart = [[0, 0, 0], [2, 1, 0], [4, 0, 0], [2, 3, 0]]
    bowtie = [[0, 0, 0], [1, 1, 0], [1, 0, 0], [0, 1, 0]]
    mesh = quads_mesh(square, pole, warped, dart, bowtie)
    hits = found(mesh)
    assert set(hits) == {"Q201", "Q202", "Q203", "Q204"}
    assert hits["Q201"][0] == [1] and hits["Q201"][1][0] == 0
    assert hits["Q202"][0] == [2]
    np.testing.assert_allclose(hits["Q202"][1], [60.0])
    assert hits["Q203"][0] == [3] and hits["Q203"][1][0] > 180
    assert hits["Q204"][0] == [4] and hits["Q204"][1][0] == 0.5
    assert "Q202" not in found(mesh, thresholds={"Q202": 61})
    np.testing.assert_allclose(found(mesh, diagonal="13")["Q202"][1], [np.degrees(np.arccos(1 / np.sqrt(3)))])


def test_uv_rules():
    quad = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    mirrored = np.array(SQUARE_UV)[:, ::-1]  # clockwise
    collapsed = [[0.5, 0.5]] * 4
    mesh = quads_mesh(quad, quad, quad, texcoords=[SQUARE_UV, mirrored, collapsed])
    hits = found(mesh, select=["Q3"])
    assert hits["Q301"][0] == [2]
    assert hits["Q302"][0] == [1]
    np.testing.assert_allclose(hits["Q302"][1], [-1])


def test_no_faces():
    mesh = make_mesh([], np.zeros((3, 3)))
    hits = lint_mesh(mesh, Settings())
    assert [(h.code, h.faces.tolist(), h.lines.tolist()) for h in hits] == [("Q205", [-1], [1])]
    assert lint_mesh(mesh, Settings(ignore=["Q205"])) == []
    assert lint_mesh(make_mesh([], np.zeros((0, 3))), Settings()) == []


def test_select_and_ignore():
    mesh = quads_mesh(TRAPEZOID, [[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, 1, 0]], texcoords=[SQUARE_UV] * 2)
    assert set(found(mesh)) == {"Q101", "Q201"}
    assert set(found(mesh, select=["Q2"])) == {"Q201"}
    assert set(found(mesh, ignore=["Q1"])) == {"Q201"}


def test_batches_give_the_same_findings_as_one_batch(monkeypatch):
    rng = np.random.default_rng(4)
    quads = rng.normal(size=(50, 4, 3)) * [1, 1, 0.1] + np.array(TRAPEZOID) * 3
    mesh = quads_mesh(*quads, texcoords=list(rng.normal(size=(50, 4, 2))))
    whole = lint_mesh(mesh, Settings())
    whole_routing = quad_uv_error(mesh)
    monkeypatch.setattr(affinity.lint, "BATCH_SIZE", 7)
    batched = lint_mesh(mesh, Settings())
    assert [h.code for h in batched] == [h.code for h in whole]
    for a, b in zip(whole, batched):
        np.testing.assert_array_equal(a.faces, b.faces)
        np.testing.assert_array_equal(a.values, b.values)
    np.testing.assert_array_equal(quad_uv_error(mesh)[1], whole_routing[1])


# --- image headers -----------------------------------------------------------------


@pytest.mark.parametrize(
    "name, options",
    [
        ("t.png", {}),
        ("t.jpg", {}),
        ("t.jpg", {"progressive": True}),
        ("t.jpg", {"exif": b"Exif\x00\x00" + bytes(3000)}),
        ("t.bmp", {}),
        ("t.tga", {}),
        ("t.tga", {"compression": "tga_rle"}),
    ],
)
def test_image_size_reads_headers(tmp_path, name, options):
    pil = pytest.importorskip("PIL.Image")
    path = tmp_path / name
    pil.new("RGB", (300, 123), "red").save(path, **options)
    assert image_size(path) == (300, 123)
    assert image_size(str(path)) == (300, 123)


def test_image_size_of_what_is_not_a_readable_image(tmp_path):
    (tmp_path / "junk.png").write_bytes(b"not an image at all")
    (tmp_path / "empty.jpg").write_bytes(b"")
    (tmp_path / "cut.jpg").write_bytes(b"\xff\xd8\xff\xe0\x00\x10JFIF")
    (tmp_path / "cut.png").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00")
    (tmp_path / "loop.jpg").write_bytes(b"\xff\xd8\xff\xe0\x00\x00" * 2)  # segment length 0
    for name in ["junk.png", "empty.jpg", "cut.jpg", "cut.png", "loop.jpg", "missing.png"]:
        assert image_size(tmp_path / name) is None
    assert image_size(tmp_path) is None
    assert image_size(None) is None


def test_check_path_does_not_import_pillow():
    import subprocess
    import sys

    code = "import sys, affinity.lint; assert 'PIL' not in sys.modules; assert 'igl' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


# --- the real corpus ---------------------------------------------------------------


@pytest.fixture
def load_corpus_mesh(shared_meshes):
    return lambda name: load(str(shared_meshes / name))


def test_corpus_uv_flips_match_the_manifest_winding(manifest_entry, load_corpus_mesh):
    entry = manifest_entry
    mesh = load_corpus_mesh(entry["file"])
    hits = found(mesh, select=["Q301", "Q302"])
    assert len(hits.get("Q302", ([], []))[0]) == entry["uv_quad_winding"]["cw"]
    assert len(hits.get("Q301", ([], []))[0]) == entry["uv_quad_winding"]["zero_area"]
    for h in lint_mesh(mesh, Settings()):
        assert np.isfinite(h.values).all()


def test_corpus_makehuman_paper_score_flags_most_quads_but_few_move_a_texel(load_corpus_mesh):
    mesh = load_corpus_mesh("makehuman_base_hm08.obj")
    quads = mesh.counts()["quads"]
    paper = found(mesh, measure="barycentric", select=["Q101"])["Q101"][0]
    visible = found(mesh, thresholds={"Q101": 1.0}, select=["Q101"])["Q101"][0]
    assert 0.90 < len(paper) / quads < 0.95  # measured 92.2%
    assert 0.003 < len(visible) / quads < 0.0042  # measured 0.357% (the old centre-shift formula: 0.60%)


def test_corpus_sphere_pole_quads_are_degenerate_and_scored_finitely(load_corpus_mesh):
    mesh = load_corpus_mesh("gen_uv_sphere_64x32.obj")
    assert len(found(mesh, select=["Q201"])["Q201"][0]) == 128
    _faces, m = quad_uv_error(mesh, diagonal="both")
    # The split's worst error on a pole quad is its whole u width, 1/64 (a quarter of it at the centre).
    assert np.isfinite(m).all() and m.max() == pytest.approx(1 / 64)


def test_a_threshold_of_minus_infinity_reports_every_quad_for_every_rule():
    """The report scores every quad by linting at -inf; no rule may drop quads then."""
    from affinity.scenes import demo_sphere

    sphere = demo_sphere()
    for code in ("Q101", "Q103"):
        hits = lint_mesh(sphere, Settings(select=[code], thresholds={code: -np.inf}))
        assert len(hits) == 1 and len(hits[0]) == 128, code
        assert np.isfinite(hits[0].values).all()


def test_uv_flipped_leaves_what_a_configured_uv_degenerate_threshold_calls_degenerate():
    quad = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    thin_mirror = np.array(SQUARE_UV)[:, ::-1] * [1.0, 1e-4]  # clockwise, area 1e-4 of its size squared
    mesh = quads_mesh(quad, texcoords=[thin_mirror])
    default = found(mesh, select=["Q3"])
    assert "Q301" not in default and default["Q302"][0] == [0]
    configured = found(mesh, select=["Q3"], thresholds={"Q301": 1e-2})
    assert configured["Q301"][0] == [0] and "Q302" not in configured
