"""USD asset trees as studios ship them (issue 55): the Open Chess Set and a miniature of its layout.

MaterialX reached through a parent scope's uncomposable ``.mtlx`` reference, bound inside a variant: the
finding names the texture and its role and is read through it; the truth for C is the same mesh read as
an OBJ whose MTL names the same texture (another loader, another path to the texture). usd-core's
diagnostics never reach stderr raw.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from helpers.cli import run
from helpers.usd_studio import AUTHORED, PRIMS, obj_twin, studio_asset

pytest.importorskip("pxr", reason="needs the usd extra (usd-core)")

#: A usd-core diagnostic printed raw: "Warning: in _ReportErrors at line ... of .../stage.cpp -- ..."
RAW_DIAGNOSTIC = re.compile(r"^(Warning|Error|Status|Coding Error): in \w+ at line \d+", re.MULTILINE)
PIECES = ("Bishop", "Chessboard", "King", "Knight", "Pawn", "Queen", "Rook")


def check_json(*args: str, cwd: Path | None = None, status: int = 1) -> tuple[dict, str]:
    result = run("check", "--no-cache", "--isolated", "--format", "json", *args, cwd=cwd)
    assert result.returncode == status, result.stderr
    return json.loads(result.stdout), result.stderr


# -- the miniature ---------------------------------------------------------------------------------------

def test_materialx_on_a_parent_scope_bound_in_a_variant_is_read_through_its_texture(tmp_path):
    stage = studio_asset(tmp_path)
    twin, _ = check_json(str(obj_twin(tmp_path, stage.parent / "assets/Piece/tex/black.png")))
    report, stderr = check_json("set.usda", cwd=tmp_path)
    findings = report["findings"]
    assert [(f["code"], f["face"]) for f in findings] == [("Q101", 0), ("Q101", 1)]
    for found, truth in zip(findings, twin["findings"]):
        assert (found["texture"], found["role"], found["unit"]) == ("assets/Piece/tex/black.png", "base colour",
                                                                     "1/255")
        assert (found["value"], found["level"], found["shift"]) == (truth["value"], truth["level"],
                                                                    pytest.approx(truth["shift"]))
        assert found["prims"] == PRIMS and found["layer_prim"] == AUTHORED
        assert "assumed" not in found["message"]
    assert not RAW_DIAGNOSTIC.search(stderr)
    notes = [line for line in stderr.splitlines() if ": note: " in line]
    assert notes == ["set.usda: note: assets/Piece/Piece_look.usd references assets/Piece/Piece_mat.mtlx "
                     "(at </Piece/Materials>), which usd-core cannot compose (cannot determine file format): "
                     "its materials are read from its MaterialX XML"]


def test_the_stage_selection_decides_the_texture_and_all_variants_reads_every_binding(tmp_path):
    """/Set/B alone selects White (a flat texture: the crease does not show, C = 0); --all-variants also reads
    Black's stripes, and the worst decides: the value of the Black selection."""
    stage = studio_asset(tmp_path)
    text = stage.read_text()
    white = tmp_path / "white.usda"
    white.write_text(text[:text.index('    def Xform "A"')] + text[text.index('    def Xform "B"'):])
    black, _ = check_json(str(stage))
    selected, _ = check_json("--select", "Q101", str(white), status=0)
    assert {f["texture"] for f in selected["findings"]} == {"assets/Piece/tex/white.png"}
    assert {f["value"] for f in selected["findings"]} == {0.0}
    every, _ = check_json("--all-variants", str(white))
    assert [(f["face"], f["value"], f["texture"]) for f in every["findings"]] == \
        [(f["face"], f["value"], f["texture"]) for f in black["findings"]]


FILES = ["assets/Piece/Piece.usd", "assets/Piece/Piece_geom.usd", "assets/Piece/Piece_payload.usd", "set.usda"]


def test_a_folder_run_reports_each_authored_mesh_once_with_every_referencing_prim(tmp_path):
    """Four files compose the piece's mesh; the set's two prims see it through textures: its findings come
    once, from the set (the most referencing prims), as the set alone reports them, listing all five prims."""
    studio_asset(tmp_path)
    alone, _ = check_json("set.usda", cwd=tmp_path)
    folder, _ = check_json(".", cwd=tmp_path)
    assert [(f["path"], f["code"], f["face"], f["value"], f["level"]) for f in folder["findings"]] == \
        [(f["path"], f["code"], f["face"], f["value"], f["level"]) for f in alone["findings"]]
    for f in folder["findings"]:
        assert (Path(f["layer"]).name, f["layer_prim"]) == ("Piece_geom.usd", AUTHORED)
        assert f["prims"] == [*PRIMS, *(f"{path}:{AUTHORED}" for path in FILES[:3])]
    assert {entry["path"]: entry.get("findings") for entry in folder["files"]} == \
        {**dict.fromkeys(FILES[:3], 0), "assets/Piece/Piece_look.usd": 0, "set.usda": 2}
    text = run("check", "--no-cache", "--isolated", ".", cwd=tmp_path).stdout
    assert len([line for line in text.splitlines() if ": Q101 " in line]) == 2


@pytest.mark.parametrize("fmt", ["json", "text", "sarif", "github", "junit"])
def test_the_shards_of_a_folder_run_merge_into_the_whole_run(tmp_path, fmt):
    """Every format gives the mesh once (its two findings), and the shards merge into the whole run."""
    studio_asset(tmp_path)
    options = ["--no-cache", "--isolated", "."]
    whole = run("check", *options, "--format", fmt, cwd=tmp_path)
    assert "Q101" in whole.stdout
    assert not any(f"{path}:/Piece/Geom/Render:face" in whole.stdout or f"file={path}" in whole.stdout
                   for path in FILES[:3])  # no file but the set locates a finding
    for k in (1, 2, 3):
        shard = run("check", *options, "--shard", f"{k}/3", "--format", "json", "-o", f"shard{k}.json", cwd=tmp_path)
        assert shard.returncode in (0, 1), shard.stderr
    merged = run("merge", "shard1.json", "shard2.json", "shard3.json", "--format", fmt, cwd=tmp_path)
    assert (merged.returncode, merged.stdout) == (whole.returncode, whole.stdout)


# -- the Open Chess Set --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def chess_set_check(shared_meshes) -> tuple[dict, str]:
    stage = shared_meshes / "usd" / "OpenChessSet" / "chess_set.usda"
    if not stage.is_file():
        pytest.skip("the Open Chess Set is not in ../shared/meshes/usd")
    return check_json(str(stage))


@pytest.mark.slow  # the whole chess set: a minute or more
def test_the_chess_set_reads_its_2048_textures_through_materialx(chess_set_check, shared_meshes):
    from PIL import Image

    report, _ = chess_set_check
    q101 = [f for f in report["findings"] if f["code"] == "Q101"]
    assert len(q101) > 1000
    folder = shared_meshes / "usd" / "OpenChessSet"
    sizes = {}
    for f in q101:
        piece = f["prim"].split("/")[-3].rstrip("LR") if "Pawn" not in f["prim"] else "Pawn"
        assert f["texture"].startswith(f"assets/{'Chessboard' if 'Chessboard' in f['prim'] else piece}/tex/"), f
        assert f["unit"] == ("degrees" if f["role"] == "normal" else "1/255"), f
        assert f["role"] in ("base colour", "normal", "scalar") and "assumed" not in f["message"]
        if f["texture"] not in sizes:
            with Image.open(folder / f["texture"]) as image:
                sizes[f["texture"]] = image.size
    assert set(sizes.values()) == {(2048, 2048)}


@pytest.mark.slow  # the whole chess set: a minute or more
def test_the_chess_set_says_each_uncomposable_look_once_and_nothing_raw(chess_set_check):
    _, stderr = chess_set_check
    assert not RAW_DIAGNOSTIC.search(stderr)
    notes = [line for line in stderr.splitlines() if "cannot compose" in line]
    assert sorted(re.search(r"assets/(\w+)/\1_look\.usd references \S*assets/\1/\1_mat\.mtlx", line).group(1)
                  for line in notes) == list(PIECES)


def test_a_look_layer_is_a_checked_file_and_fail_on_skip_passes_the_asset_folder(tmp_path):
    studio_asset(tmp_path)
    report, _ = check_json(".", cwd=tmp_path)
    files = {entry["path"]: entry for entry in report["files"]}
    look = files["assets/Piece/Piece_look.usd"]
    assert "skipped" not in look and (look["faces"], look["findings"]) == (0, 0)
    assert not [entry for entry in report["files"] if "skipped" in entry]
    gated = run("check", "--no-cache", "--isolated", "--format", "json", "--fail-on-skip", ".", cwd=tmp_path)
    assert (gated.returncode, json.loads(gated.stdout)["summary"]) == (1, report["summary"])


@pytest.fixture(scope="module")
def chess_folder_check(shared_meshes) -> tuple[dict, str]:
    folder = shared_meshes / "usd" / "OpenChessSet"
    if not folder.is_dir():
        pytest.skip("the Open Chess Set is not in ../shared/meshes/usd")
    return check_json("--fail-on-skip", str(folder))


@pytest.mark.slow  # the whole chess set: a minute or more
def test_the_chess_set_folder_reports_each_authored_mesh_once(chess_folder_check, chess_set_check):
    """The truth is the stage alone: it composes every authored mesh, each once (its own sharing), so over the
    folder the findings per authored mesh (layer, prim in it) are the stage's, and their number the same."""
    folder, _ = chess_folder_check
    stage, _ = chess_set_check

    def by_authored_mesh(report):
        sources = {(entry["path"], prim): tuple(source) for entry in report["files"]
                   for prim, source in entry.get("prim_sources", {}).items()}
        return sorted((*sources[f["path"], f["prim"]], f["code"], f["face"], f["level"], f["value"])
                      for f in report["findings"])

    assert len(folder["findings"]) == len(stage["findings"])
    assert by_authored_mesh(folder) == by_authored_mesh(stage)
    for f in folder["findings"]:
        piece = Path(f["layer"]).name.removesuffix("_geom.usd")
        files = {f["path"], *(prim.rsplit(":", 1)[0] for prim in f["prims"] if ":" in prim)}
        assert {Path(name).name for name in files} == {f"{piece}.usd", f"{piece}_geom.usd", f"{piece}_payload.usd",
                                                       "chess_set.usda"}, f


@pytest.mark.slow  # the whole chess set: a minute or more
def test_fail_on_skip_passes_the_chess_set_folder_as_without_it(chess_folder_check):
    """The run has errors (exit 1 without the flag); with it, no look layer is a skip, so still 1. Each look's
    uncomposable .mtlx is said once in the run, though four files compose it."""
    folder, stderr = chess_folder_check  # check_json asserted exit 1
    assert folder["summary"]["skipped"] == 0 and "skipped" not in stderr
    assert not RAW_DIAGNOSTIC.search(stderr)
    assert len([line for line in stderr.splitlines() if "cannot compose" in line]) == len(PIECES)
    looks = [entry for entry in folder["files"] if entry["path"].endswith("_look.usd")]
    assert len(looks) == len(PIECES) and all(entry["findings"] == 0 for entry in looks)
