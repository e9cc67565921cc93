"""The result cache: same output as a fresh check, invalidated by exactly what a file's result depends on."""

from __future__ import annotations

import os
import sqlite3
import struct
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import run
from helpers.quads import SQUARE, UNIT_UV, quad_obj, sample_run, trapezoid
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import affinity
from affinity.findings import FileReport, RuleHits, report_from_bytes, report_to_bytes
from affinity.pipeline import cache as cache_module
from affinity.pipeline import check as check_module
from affinity.pipeline.cache import DB_NAME, ResultCache, tool_fingerprint
from affinity.pipeline.check import check_files
from affinity.settings import Settings


def png_header(width: int, height: int) -> bytes:
    """The first bytes of a PNG: enough for the texel unit, which reads only the image size."""
    return b"\x89PNG\r\n\x1a\n" + struct.pack(">I4sII", 13, b"IHDR", width, height) + b"\x08\x02\x00\x00\x00"


@pytest.fixture
def assets(tmp_path: Path, an_hour_later) -> Path:
    """``textured.obj`` (mtllib -> map_Kd tex.png, 64 px) with two disaffine quads, ``plain.obj`` with one."""
    (tmp_path / "tex.png").write_bytes(png_header(64, 64))
    (tmp_path / "look.mtl").write_text("newmtl wood\nmap_Kd tex.png\n")
    header = "mtllib look.mtl\nusemtl wood"
    (tmp_path / "textured.obj").write_text(quad_obj([(trapezoid(), UNIT_UV), (trapezoid(0.5, 3), UNIT_UV)],
                                                    header=header))
    (tmp_path / "plain.obj").write_text(quad_obj([(trapezoid(0.25), UNIT_UV), (SQUARE, UNIT_UV)]))
    return tmp_path


def same_report(a: FileReport, b: FileReport) -> bool:
    """Field by field, arrays by dtype and bytes (NaN included)."""
    def arrays_equal(x, y):
        return (x is None and y is None) or (
            x is not None and y is not None and x.dtype == y.dtype and x.shape == y.shape
            and x.tobytes() == y.tobytes())

    plain = ("path", "counts", "group_names", "error", "error_line", "skipped", "up_axis", "meters_per_unit", "notes")
    return (
        all(getattr(a, f) == getattr(b, f) for f in plain)
        and arrays_equal(a.prim_face_start, b.prim_face_start)
        and len(a.hits) == len(b.hits)
        and all(
            h.code == k.code and h.threshold == k.threshold
            and all(arrays_equal(getattr(h, f), getattr(k, f)) for f in ("faces", "lines", "values", "groups"))
            for h, k in zip(a.hits, b.hits))
    )


def cached_run(folder: Path, tasks, tool: str = "tool-1") -> list[FileReport]:
    cache = ResultCache(str(folder), tool=tool)
    try:
        return check_files(tasks, jobs=1, cache=cache)
    finally:
        cache.close()


def tasks_of(folder: Path, settings: Settings | None = None):
    return [(str(folder / name), settings or Settings()) for name in ("plain.obj", "textured.obj")]


def test_reports_round_trip_exactly():
    usd = FileReport(
        "stage.usda", counts={"faces": 5, "quads": 4, "triangles": 1, "ngons": 0},
        hits=[RuleHits("Q101", np.array([4, 0], dtype=np.int64), np.array([0, 0], dtype=np.int64),
                       np.array([np.inf, 1e-300]), 0.5, np.array([1, 0], dtype=np.int32)),
              RuleHits("Q202", np.array([3]), np.array([0]), np.array([np.nan]), 1.0, np.array([1], dtype=np.int32))],
        group_names=["/World/a", "/World/b ü"], prim_face_start=np.array([0, 2, 5], dtype=np.int64),
        up_axis="Z", meters_per_unit=0.01, notes=["2 subsets not checked"])
    for report in [usd, *sample_run().reports, FileReport("empty.obj", counts={"faces": 0})]:
        blob = report_to_bytes(report)
        assert len(blob) < 4000
        assert same_report(report_from_bytes(blob), report)
    assert not same_report(report_from_bytes(report_to_bytes(usd)), sample_run().reports[0])


def test_damaged_blob_raises_value_error():
    blob = report_to_bytes(sample_run().reports[0])
    with pytest.raises(ValueError):
        report_from_bytes(blob[: len(blob) // 2])


def test_unchanged_files_are_neither_read_nor_hashed_again(assets, tmp_path_factory, monkeypatch, counting):
    folder = tmp_path_factory.mktemp("cache")
    first = cached_run(folder, tasks_of(assets))
    assert counting.paths == ["plain.obj", "textured.obj"]
    assert [r.n_findings for r in first] == [1, 2]

    def no_reading(*args, **kwargs):
        raise AssertionError("read a file the cache knows")

    monkeypatch.setattr(cache_module, "_hash_file", no_reading)
    monkeypatch.setattr(check_module, "check_file", no_reading)
    second = cached_run(folder, tasks_of(assets))
    assert all(same_report(a, b) for a, b in zip(first, second))


def test_each_input_invalidates_exactly_its_results(assets, tmp_path_factory, counting):
    folder = tmp_path_factory.mktemp("cache")
    first = cached_run(folder, tasks_of(assets))
    counting.paths.clear()

    (assets / "plain.obj").write_text(quad_obj([(trapezoid(0.25), UNIT_UV), (trapezoid(0.5), UNIT_UV)]))
    changed = cached_run(folder, tasks_of(assets))
    assert counting.paths == ["plain.obj"] and changed[0].n_findings == 2
    counting.paths.clear()

    # The texture's size is the texel unit: twice the size, twice the misplacement in texels.
    (assets / "tex.png").write_bytes(png_header(128, 128))
    retextured = cached_run(folder, tasks_of(assets))
    assert counting.paths == ["textured.obj"]
    np.testing.assert_allclose(retextured[1].hits[0].values, 2 * first[1].hits[0].values)
    counting.paths.clear()

    cached_run(folder, tasks_of(assets, Settings(thresholds={"Q101": 100.0})))
    assert counting.paths == ["plain.obj", "textured.obj"]
    counting.paths.clear()

    cached_run(folder, tasks_of(assets), tool="tool-2")
    assert counting.paths == ["plain.obj", "textured.obj"]
    counting.paths.clear()

    cached_run(folder, tasks_of(assets))
    assert counting.paths == []


def test_the_tool_fingerprint_follows_the_version(monkeypatch):
    before = tool_fingerprint()
    monkeypatch.setattr(affinity, "__version__", affinity.__version__ + ".post1")
    assert tool_fingerprint() != before


def test_a_file_rewritten_within_its_mtime_is_checked_again(tmp_path, tmp_path_factory):
    """Same size, same mtime_ns (a coarse file-system clock): only the content hash can tell."""
    mesh = tmp_path / "fresh.obj"
    disaffine = quad_obj([(trapezoid(0.5), UNIT_UV)])
    affine = quad_obj([(SQUARE, UNIT_UV)])
    affine += "#" * (len(disaffine) - len(affine) - 1) + "\n"
    assert len(affine) == len(disaffine)
    mesh.write_text(disaffine)
    stamp = mesh.stat().st_mtime_ns
    folder = tmp_path_factory.mktemp("cache")
    assert cached_run(folder, [(str(mesh), Settings())])[0].n_findings == 1
    mesh.write_text(affine)
    os.utime(mesh, ns=(stamp, stamp))
    assert cached_run(folder, [(str(mesh), Settings())])[0].n_findings == 0


def test_internal_errors_are_never_stored(assets, tmp_path_factory, monkeypatch):
    folder = tmp_path_factory.mktemp("cache")
    monkeypatch.setattr(check_module, "check_file",
                        lambda path, settings, usd=None, source=None: FileReport(path, error="internal error: boom",
                                                                    transient=True))
    assert cached_run(folder, tasks_of(assets))[0].error == "internal error: boom"
    monkeypatch.undo()
    assert [r.error for r in cached_run(folder, tasks_of(assets))] == [None, None]


def test_old_and_excess_entries_are_pruned(assets, tmp_path_factory, monkeypatch):
    folder = tmp_path_factory.mktemp("cache")
    cached_run(folder, tasks_of(assets))
    db = sqlite3.connect(folder / DB_NAME)
    db.execute("INSERT INTO results VALUES ('stale', x'00', 0, '')")
    db.commit()
    sizes = dict(db.execute("SELECT key, LENGTH(report) FROM results").fetchall())
    newest = max(sizes, key=lambda k: k != "stale")
    db.execute("UPDATE results SET used = used + 1 WHERE key = ?", (newest,))
    db.commit()
    monkeypatch.setattr(cache_module, "MAX_BYTES", sizes[newest])
    ResultCache(str(folder), tool="tool-1").close()
    assert [k for (k,) in db.execute("SELECT key FROM results")] == [newest]


def write_assets_dir(tmp_path: Path) -> Path:
    folder = tmp_path / "assets"
    folder.mkdir()
    for i in range(4):
        (folder / f"m{i}.obj").write_text(quad_obj([(trapezoid(0.2 * (k + 1), 3 * k), UNIT_UV) for k in range(i + 1)]))
    (folder / "broken.obj").write_text("v 0 0 0\nf 1 2 9\n")
    return folder


def check_with_cache(folder: Path, cache_dir: Path | str, *extra: str):
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("AFFINITY_CACHE_DIR", str(cache_dir))
        return run("check", "--verbose", *extra, ".", cwd=folder)


def test_second_run_gives_identical_output(tmp_path):
    folder = write_assets_dir(tmp_path)
    fresh = run("check", "--verbose", "--no-cache", ".", cwd=folder)
    for fmt in ("text", "json"):
        first = check_with_cache(folder, tmp_path / "cache", "--format", fmt)
        second = check_with_cache(folder, tmp_path / "cache", "--format", fmt)
        assert first.returncode == second.returncode == 2
        assert (first.stdout, first.stderr) == (second.stdout, second.stderr)
    assert (second.stdout, second.stderr) != (fresh.stdout, fresh.stderr)  # json against text
    assert check_with_cache(folder, tmp_path / "cache").stdout == fresh.stdout
    assert (tmp_path / "cache" / DB_NAME).is_file()


def test_unwritable_cache_folder_warns_once_and_checks(tmp_path):
    folder = write_assets_dir(tmp_path)
    fresh = run("check", "--verbose", "--no-cache", ".", cwd=folder)
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("")
    result = check_with_cache(folder, blocker / "cache")
    warnings = [line for line in result.stderr.splitlines() if "result cache" in line]
    assert len(warnings) == 1 and "warning" in warnings[0] and "Traceback" not in result.stderr
    assert result.stdout == fresh.stdout and result.returncode == fresh.returncode == 2


def test_damaged_cache_warns_is_replaced_and_still_checks(tmp_path):
    folder = write_assets_dir(tmp_path)
    fresh = run("check", "--verbose", "--no-cache", ".", cwd=folder)
    cache_dir = tmp_path / "cache"
    cache_dir.mkdir()
    (cache_dir / DB_NAME).write_bytes(b"\x00garbage" * 500)
    damaged = check_with_cache(folder, cache_dir)
    assert damaged.stdout == fresh.stdout and damaged.returncode == 2
    assert damaged.stderr.count("result cache") == 1 and "damaged" in damaged.stderr
    db = sqlite3.connect(cache_dir / DB_NAME)
    db.execute("UPDATE results SET report = x'51415231ff'")  # every entry now a broken blob
    db.commit()
    broken_entries = check_with_cache(folder, cache_dir)
    assert broken_entries.stdout == fresh.stdout and broken_entries.stderr.count("damaged entry") == 1
    healed = check_with_cache(folder, cache_dir)
    assert healed.stdout == fresh.stdout and healed.stderr == fresh.stderr


def test_no_cache_flag_and_config_key_leave_the_cache_alone(tmp_path):
    folder = write_assets_dir(tmp_path)
    check_with_cache(folder, tmp_path / "off", "--no-cache")
    (folder / "affinity.toml").write_text("cache = false\n")
    check_with_cache(folder, tmp_path / "off-too")
    assert not (tmp_path / "off").exists() and not (tmp_path / "off-too").exists()
    (folder / "affinity.toml").write_text("cache = 'yes'\n")
    bad = check_with_cache(folder, tmp_path / "off-too")
    assert bad.returncode == 2 and "cache: expected true or false" in bad.stderr


def test_usd_sublayer_edits_invalidate_the_stage(tmp_path, tmp_path_factory, counting, an_hour_later):
    pytest.importorskip("pxr")
    from pxr import Sdf, Usd, UsdGeom

    sub = tmp_path / "geometry.usda"
    stage = Usd.Stage.CreateNew(str(sub))
    mesh = UsdGeom.Mesh.Define(stage, "/World/quad")
    mesh.CreatePointsAttr([(-1, 0, 0), (1, 0, 0), (0.5, 1, 0), (-0.5, 1, 0)])
    mesh.CreateFaceVertexCountsAttr([4])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    stage.GetRootLayer().Save()
    root = Sdf.Layer.CreateNew(str(tmp_path / "shot.usda"))
    root.subLayerPaths.append("geometry.usda")
    root.Save()
    folder = tmp_path_factory.mktemp("cache")
    first = cached_run(folder, [(str(tmp_path / "shot.usda"), Settings())])
    assert counting.paths == ["shot.usda"] and first[0].counts["quads"] == 1
    cached_run(folder, [(str(tmp_path / "shot.usda"), Settings())])
    assert counting.paths == ["shot.usda"]
    mesh.CreateFaceVertexCountsAttr([3])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2])
    stage.GetRootLayer().Save()
    second = cached_run(folder, [(str(tmp_path / "shot.usda"), Settings())])
    assert counting.paths == ["shot.usda", "shot.usda"] and second[0].counts["triangles"] == 1


def test_a_stage_read_without_usd_core_is_not_served_to_a_run_with_it(tmp_path, monkeypatch):
    stage = tmp_path / "stage.usda"
    stage.write_text("#usda 1.0\n")
    cache = ResultCache(str(tmp_path / "cache"), tool="t")
    with_reader = cache.key(str(stage), Settings())
    monkeypatch.setitem(sys.modules, "pxr", None)
    assert cache.key(str(stage), Settings()) != with_reader
    cache.close()


# -- the mtllib scan of the content hash ------------------------------------------------------------

_LINES = [b"mtllib a.mtl", b"  mtllib b c.mtl", b"\tmtllib d.mtl # the look", b"mtllib e#f.mtl", b"# mtllib g.mtl",
          b"usemtl mtllib", b"xmtllib h.mtl", b"mtllibi.mtl", b"mtllib", b"mtllib # nothing", b"mtllib j.mtl mtllib",
          b"v 0 0 0", b"vt 0.5 0.5", b"f 1 2 3", b"g mtllib k.mtl", b"mtllib l.mtl\r", b"mtllib caf\xe9.mtl", b""]


def named_libraries(text: bytes) -> list[str]:
    """The OBJ rule, line by line: a line whose first word is ``mtllib`` names the words after it up to a comment."""
    names = []
    for line in text.split(b"\n"):
        words = line.split()
        if words and words[0] == b"mtllib":
            comment = next((k for k, word in enumerate(words) if word.startswith(b"#")), len(words))
            names += [os.fsdecode(b" ".join(words[1:comment]))] if comment > 1 else []
    return names


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lines=st.lists(st.sampled_from(_LINES), max_size=30), newline=st.booleans())
def test_the_cache_and_the_loader_read_the_libraries_the_obj_rule_names(tmp_path, lines, newline):
    from affinity.loaders.references import obj_resources

    text = b"\n".join(lines) + b"\n" * newline
    path = tmp_path / "mesh.obj"
    path.write_bytes(text)
    expected = list(dict.fromkeys(os.path.abspath(tmp_path / name) for name in named_libraries(text)))
    _, deps = cache_module._hash_file(str(path))
    assert deps == expected
    resources = obj_resources(str(path), text)  # what load_obj puts in Mesh.resources
    assert [os.path.abspath(r.path) for r in resources if r.role == "mtllib"] == expected


def test_a_nul_byte_in_an_mtllib_name_is_one_clear_line_with_the_cache_on(tmp_path):
    """No file is named with a NUL byte (os.stat raises ValueError, not OSError): the cache's key treats the
    resource as missing, and the loader refuses the binary byte naming the line (found by the fuzzer)."""
    (tmp_path / "nul.obj").write_bytes(b"mtllib a\0b.mtl\n" + quad_obj([(SQUARE, UNIT_UV)]).encode())
    done = run("check", "nul.obj", cwd=tmp_path)
    assert done.returncode != 0 and "Traceback" not in done.stderr
    assert "nul.obj:1:" in done.stdout + done.stderr and "0x00" in done.stdout + done.stderr
