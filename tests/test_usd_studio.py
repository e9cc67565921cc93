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


# -- the Open Chess Set --------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def chess_set_check(shared_meshes) -> tuple[dict, str]:
    stage = shared_meshes / "usd" / "OpenChessSet" / "chess_set.usda"
    if not stage.is_file():
        pytest.skip("the Open Chess Set is not in ../shared/meshes/usd")
    return check_json(str(stage))


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


def test_the_chess_set_says_each_uncomposable_look_once_and_nothing_raw(chess_set_check):
    _, stderr = chess_set_check
    assert not RAW_DIAGNOSTIC.search(stderr)
    notes = [line for line in stderr.splitlines() if "cannot compose" in line]
    assert sorted(re.search(r"assets/(\w+)/\1_look\.usd references assets/\1/\1_mat\.mtlx", line).group(1)
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
