"""``affinity merge`` trusts none of its inputs (issue 53): a FIFO, ``/dev/zero``, a file over the result budget,
JSON nested 100,000 deep, ``1e400``, an integer of 5,000 digits and ``NaN`` are each one line and exit 2,
nothing written; the USD validators' MaterialX read refuses a FIFO as check's loaders do (it used to block
for good in ElementTree.parse)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest
from helpers.cli import TRAPEZOID, run, write

from affinity.shards.results import RESULT_BUDGET

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="makes a FIFO")


def a_shard(tmp_path) -> str:
    mesh = write(tmp_path, "m.obj", TRAPEZOID)
    return run("check", "--shard", "1/1", "--format", "json", str(mesh)).stdout


def hostile_inputs(tmp_path) -> dict[str, tuple[str, str]]:
    """name -> (path, what its one line says)."""
    os.mkfifo(tmp_path / "fifo.json")
    big = tmp_path / "big.json"
    with open(big, "wb") as f:
        f.truncate(RESULT_BUDGET + 1)  # sparse: no gigabyte written
    shard = a_shard(tmp_path)
    return {
        "fifo": (str(tmp_path / "fifo.json"), "is a FIFO (named pipe), not a regular file: not read"),
        "device": ("/dev/zero", "is a character device, not a regular file: not read"),
        "big": (str(big), "is 1 GiB, over the 1 GiB budget of a check result: not read"),
        "deep": (str(write(tmp_path, "deep.json", "[" * 100_000 + "]" * 100_000)),
                 "not a check result: JSON nested deeper than Python's reader takes"),
        "1e400": (str(write(tmp_path, "e400.json", shard.replace('"faces":1,', '"faces":1e400,', 1))),
                  "not JSON: number out of range: 1e400"),
        "huge int": (str(write(tmp_path, "int.json", shard.replace('"faces":1,', f'"faces":{"9" * 5000},', 1))),
                     "not JSON: number out of range: " + "9" * 40),
        "NaN": (str(write(tmp_path, "nan.json", shard.replace('"faces":1,', '"faces":NaN,', 1))),
                "not JSON: NaN is not a JSON number"),
    }


@pytest.mark.parametrize("name", ["fifo", "device", "big", "deep", "1e400", "huge int", "NaN"])
def test_a_hostile_input_is_one_line_and_exit_2(tmp_path, name):
    path, reason = hostile_inputs(tmp_path)[name]
    out = tmp_path / "merged.json"
    done = subprocess.run([sys.executable, "-m", "affinity.cli", "merge", "--format", "json", "-o", str(out), path],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert done.stderr.splitlines() == [f"affinity merge: error: {path}: {reason}"]
    assert not out.exists()


def test_the_damaged_shards_were_whole_results_before(tmp_path):
    """The number edits above land in a real result: undone, the shard merges."""
    shard = a_shard(tmp_path)
    assert '"faces":1,' in shard
    done = run("merge", "--format", "json", str(write(tmp_path, "s.json", shard)))
    assert done.returncode == 1 and json.loads(done.stdout)["summary"]["findings"] == 1


MTLX = """<?xml version="1.0"?>
<materialx version="1.38"><surfacematerial name="M" type="material"/></materialx>
"""


def test_materialx_read_refuses_a_fifo(tmp_path):
    """The validators' path (affinity.usd.stage.check_stage) reads a stage whose material references a .mtlx
    that is a FIFO with no writer: it finishes (no texture read from it) instead of blocking; in a subprocess,
    so a regression fails on the timeout rather than hanging the suite."""
    pytest.importorskip("pxr")
    from helpers.usd_stages import looks, usd_quads

    os.mkfifo(tmp_path / "look.mtlx")
    material = '    def Material "Mx" (\n        references = @look.mtlx@</MaterialX/Materials/M>\n    )\n    {}\n'
    stage = write(tmp_path, "scene.usda", usd_quads(["Mx"]) + looks(material))
    code = textwrap.dedent(f"""
        from pxr import Usd
        from affinity.loaders.usdmaterials import mtlx_document_maps
        from affinity.usd.stage import check_stage
        assert mtlx_document_maps({str(tmp_path / "look.mtlx")!r}) == []
        check = check_stage(Usd.Stage.Open({str(stage)!r}))
        print(check.error, sorted(check.findings))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("None ")
