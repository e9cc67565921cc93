"""`affinity check --shard K/N` and `affinity merge`, as a CI matrix or a render farm runs them.

The truth for a merge is the run it stands for: `affinity check` over every file
at once, in the same folder, with the same flags. Its output in every format and
its exit code must come out of `merge` unchanged (the JSON and SARIF documents
carry no timing fields, so they are compared whole).
"""

from __future__ import annotations

import json
import shutil
from collections import Counter
from itertools import chain
from pathlib import Path

import pytest
from helpers.cli import SQUARE, run, write
from helpers.quads import quad_obj, trapezoid, trapezoids
from helpers.sarif import assert_valid

from affinity.shards.selection import shard_of

FORMATS = ("json", "sarif", "text", "github", "junit")
LFS_POINTER = "version https://git-lfs.github.com/spec/v1\noid sha256:0123\nsize 123456\n"
#: Shared meshes copied into the library: uv seams and atlases, n-gons, a texture with its MTL.
SHARED = ("spot_control_mesh.obj", "osd_catmark_car.obj", "osd_catmark_torus.obj", "osd_catmark_nonquads.obj",
          "gen_vase_revolution.obj", "tinyobjloader_cube_vertexcol.obj", "cube.mtl")

#: A stage with two mesh prims, each with disaffine quads (USD findings count faces within their prim).
TWO_PRIMS_USDA = """#usda 1.0
(
    upAxis = "Z"
)

def Xform "World"
{
    def Mesh "Square"
    {
        int[] faceVertexCounts = [4, 4]
        int[] faceVertexIndices = [0, 1, 2, 3, 4, 5, 6, 7]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (-1, 2, 0), (1, 2, 0), (0.25, 3, 0),
                            (-0.25, 3, 0)]
        texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0), (1, 0), (1, 1), (0, 1)] (
            interpolation = "vertex"
        )
    }

    def Mesh "Trapezoids"
    {
        int[] faceVertexCounts = [4, 4, 4]
        int[] faceVertexIndices = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]
        point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (4, 0, 0), (3.4, 1, 0),
                            (2.6, 1, 0), (5, 0, 0), (7, 0, 0), (6.05, 1, 0), (5.95, 1, 0)]
        texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1), (0, 0), (1, 0), (1, 1), (0, 1), (0, 0),
                                    (1, 0), (1, 1), (0, 1)] (
            interpolation = "vertex"
        )
    }
}
"""


def generated_files(folder: Path) -> None:
    """Small files covering every kind of file entry and finding: clean, warnings and errors of one rule
    (a visibility threshold between them), groups, a file-level finding, unreadable, skipped, USD."""
    write(folder, "affinity.toml", "texture-size = 4\n")
    write(folder, "clean.obj", SQUARE)
    write(folder, "trapezoids.obj", trapezoids([1.0, 0.9, 0.6, 0.3, 0.1]))
    (folder / "props").mkdir()
    write(folder / "props", "parts.obj", quad_obj([(trapezoid(0.5), [(0, 0), (1, 0), (1, 1), (0, 1)])] * 3,
                                                  groups=["lid", "body", "lid"]))
    write(folder / "props", "points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    write(folder, "broken.obj", SQUARE + "f 1 2 3 9\n")
    write(folder, "big.obj", LFS_POINTER)
    write(folder, "stage.usda", TWO_PRIMS_USDA)


@pytest.fixture(scope="module")
def library(tmp_path_factory, shared_meshes) -> Path:
    """A project folder (its affinity.toml is the root shards hash paths against): shared meshes and
    generated files."""
    root = tmp_path_factory.mktemp("library")
    generated_files(root)
    (root / "shared").mkdir()
    for name in SHARED:
        shutil.copy(shared_meshes / name, root / "shared" / name)
    shutil.copytree(shared_meshes / "textured", root / "shared" / "textured")
    return root


@pytest.fixture(scope="module")
def unsharded(library):
    """``affinity check .`` in every format: what each merge must give."""
    return {fmt: run("check", "--format", fmt, ".", cwd=library) for fmt in FORMATS}


def check_shards(folder: Path, n: int, out: Path, *flags: str, paths=(".",), codes: list | None = None) -> list[Path]:
    """Run shards 1..n of ``affinity check`` in ``folder`` with ``--format json``; their result files
    (their exit codes appended to ``codes`` when given)."""
    results = []
    for k in range(1, n + 1):
        result = out / f"shard-{k}-of-{n}.json"
        done = run("check", "--shard", f"{k}/{n}", "--format", "json", "-o", str(result), *flags, *paths,
                   cwd=folder)
        assert done.returncode in (0, 1, 2) and result.is_file(), done.stderr
        results.append(result)
        if codes is not None:
            codes.append(done.returncode)
    return results


def shard_files(folder: Path, n: int, *paths: str) -> list[list[str]]:
    return [run("check", "--shard", f"{k}/{n}", "--show-files", *paths, cwd=folder).stdout.splitlines()
            for k in range(1, n + 1)]


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_merged_shards_give_the_unsharded_output_in_every_format(library, unsharded, tmp_path, n):
    results = check_shards(library, n, tmp_path)
    docs = [json.loads(r.read_text()) for r in results]
    assert [doc["shard"]["index"] for doc in docs] == list(range(1, n + 1))
    listed = [[entry["path"] for entry in doc["files"]] for doc in docs]
    everything = [entry["path"] for entry in json.loads(unsharded["json"].stdout)["files"]]
    assert sorted(chain.from_iterable(listed)) == sorted(everything)  # disjoint (no file twice) and covering
    assert len(everything) == 14 and sum(map(bool, listed)) >= min(n, 3)
    for fmt in FORMATS:
        merged = run("merge", "--format", fmt, *map(str, reversed(results)), cwd=library)
        whole = unsharded[fmt]
        assert merged.returncode == whole.returncode == 2, merged.stderr  # broken.obj is unreadable
        if fmt in ("json", "sarif"):
            assert json.loads(merged.stdout) == json.loads(whole.stdout)
        else:
            assert merged.stdout == whole.stdout
        assert "broken.obj:10: Q901 unreadable" in merged.stderr


def test_the_library_exercises_what_a_merge_rebuilds(unsharded):
    """The comparison above covers USD prims, visibility thresholds, details and file-level findings."""
    doc = json.loads(unsharded["json"].stdout)
    findings = doc["findings"]
    assert {f["prim"] for f in findings if "prim" in f} == {"/World/Square", "/World/Trapezoids"}
    trapezoid_levels = {f["level"] for f in findings if f["path"] == "trapezoids.obj"}
    assert trapezoid_levels == {"warning", "error"}
    assert any(f["face"] == -1 for f in findings) and any(":" in f["message"] for f in findings)
    assert {e.get("skipped") for e in doc["files"]} >= {"lfs-pointer"} and any("error" in e for e in doc["files"])
    assert doc["summary"]["checked"] == 12


def test_merged_sarif_is_one_valid_run_and_shard_logs_have_their_own_category(library, tmp_path):
    n = 3
    categories = []
    for k in range(1, n + 1):
        log = json.loads(run("check", "--shard", f"{k}/{n}", "--format", "sarif", ".", cwd=library).stdout)
        assert_valid(log)
        (shard_run,) = log["runs"]
        categories.append(shard_run["automationDetails"]["id"])
    assert categories == [f"quad-affinity/shard-{k}-of-3/" for k in (1, 2, 3)]

    merged = json.loads(run("merge", "--format", "sarif", *map(str, check_shards(library, n, tmp_path)),
                            cwd=library).stdout)
    assert_valid(merged)
    (merged_run,) = merged["runs"]
    assert "automationDetails" not in merged_run
    assert len({r["partialFingerprints"]["quadAffinity/v1"] for r in merged_run["results"]}) == len(
        merged_run["results"]) > 100


@pytest.fixture(scope="module")
def gate_library(tmp_path_factory) -> Path:
    """Nine files: one with an error, one with a warning, one with both (a ramp of creases), six clean."""
    root = tmp_path_factory.mktemp("gate")
    write(root, "affinity.toml", "texture-size = 4\n")  # texels of a 4x4 texture: the creases 0.79 and 2.5
    for i in range(6):
        write(root, f"clean-{i}.obj", SQUARE)
    write(root, "crease.obj", trapezoids([0.1]))
    write(root, "mild.obj", trapezoids([0.9]))
    write(root, "ramp.obj", trapezoids([0.9, 0.5, 0.1, 0.02]))  # 0.79 and 1.3 texels: warnings; 2.5, 3.3: errors
    return root


@pytest.mark.parametrize(("paths", "flags", "expected"), [
    ((".",), (), 1),
    ((".",), ("--exit-zero",), 0),
    (("mild.obj", "clean-0.obj", "clean-1.obj", "clean-2.obj"), (), 0),
    (("mild.obj", "clean-0.obj", "clean-1.obj", "clean-2.obj"), ("--fail-on", "warning"), 1),
])
def test_merge_exit_code_is_the_gate_over_all_files(gate_library, tmp_path, paths, flags, expected):
    shard_codes = []
    results = check_shards(gate_library, 3, tmp_path, *flags, paths=paths, codes=shard_codes)
    merged = run("merge", *flags, *map(str, results), cwd=gate_library)
    whole = run("check", *flags, *paths, cwd=gate_library)
    assert merged.returncode == whole.returncode == expected, merged.stderr
    assert merged.stdout == whole.stdout
    if expected == 1:  # one shard fails, another passes: the merge fails as the whole run does
        assert sorted(set(shard_codes)) == [0, 1]


@pytest.fixture(scope="module")
def gate_shards(gate_library, tmp_path_factory) -> list[Path]:
    return check_shards(gate_library, 3, tmp_path_factory.mktemp("gate-shards"))


def _refused(gate_library, gate_shards, tmp_path, case) -> tuple[list[str], str]:
    """The merge inputs of a refusal ``case`` and the text the error line must hold."""
    one, two, three = map(str, gate_shards)
    if case == "missing":
        return [one, three], "affinity merge: error: shard 2/3 missing"
    if case == "twice":
        return [one, two, two, three], f"{two}: shard 2/3 given twice (also {two})"
    if case == "another run":
        other = check_shards(gate_library, 3, tmp_path, paths=("crease.obj", "mild.obj", "clean-0.obj"))[1]
        return [one, str(other), three], f"{other}: from another run"
    if case == "truncated":
        truncated = tmp_path / "truncated.json"
        run("check", "--shard", "2/3", "--max-findings", "1", "--format", "json", "-o", str(truncated), ".",
            cwd=gate_library)
        return [one, str(truncated), three], f"{truncated}: truncated by --max-findings"
    if case == "other settings":
        strict = check_shards(gate_library, 3, tmp_path, "--threshold", "0.1")[1]
        return [one, str(strict), three], f"{strict}: checked with other settings than {one} (thresholds)"
    if case == "no such file":
        return [one, two, three, str(tmp_path / "nope.json")], f"{tmp_path / 'nope.json'}: cannot read it"
    if case == "not JSON":
        return [one, two, three, str(write(tmp_path, "junk.json", "\x00junk"))], "junk.json: not JSON"
    if case == "a SARIF log":
        sarif = write(tmp_path, "log.sarif", run("check", "--format", "sarif", ".", cwd=gate_library).stdout)
        return [one, two, three, str(sarif)], f"{sarif}: not an affinity check result"
    if case == "damaged positions":
        doc = json.loads(Path(two).read_text())
        doc["shard"]["positions"] = json.loads(Path(one).read_text())["shard"]["positions"][:len(doc["files"])]
        damaged = write(tmp_path, "damaged.json", json.dumps(doc))
        return [one, str(damaged), three], f"{damaged}: its files do not fit the run's file list"
    if case == "damaged numbers":
        doc = json.loads(Path(two).read_text())
        doc["shard"]["positions"] = ["first"] * len(doc["files"])
        damaged = write(tmp_path, "damaged.json", json.dumps(doc))
        return [one, str(damaged), three], f"{damaged}: a damaged affinity check result"
    if case == "damaged levels":  # ramp.obj's worst error made a warning: above an error, no threshold explains it
        docs = [json.loads(path.read_text()) for path in gate_shards]
        (doc,) = [doc for doc in docs if any(f["path"] == "ramp.obj" for f in doc["findings"])]
        ramp = [f for f in doc["findings"] if f["path"] == "ramp.obj"]
        assert [f["level"] for f in ramp] == ["warning", "warning", "error", "error"]
        ramp[-1]["level"] = "warning"
        damaged = write(tmp_path, "damaged.json", json.dumps(doc))
        others = [str(path) for path, other in zip(gate_shards, docs) if other is not doc]
        return [str(damaged), *others], f"{damaged}: a damaged affinity check result"
    assert case == "unsharded"
    whole = write(tmp_path, "whole.json", run("check", "--format", "json", ".", cwd=gate_library).stdout)
    return [str(whole)], f"{whole}: not a shard's result (checked without --shard K/N)"


@pytest.mark.parametrize("case", ["missing", "twice", "another run", "truncated", "other settings", "no such file",
                                  "not JSON", "a SARIF log", "unsharded", "damaged positions", "damaged numbers",
                                  "damaged levels"])
def test_merge_refuses_what_is_not_one_whole_run(gate_library, gate_shards, tmp_path, case):
    inputs, line = _refused(gate_library, gate_shards, tmp_path, case)
    output = tmp_path / "merged.sarif"
    output.write_text("the previous result\n")
    merged = run("merge", "--format", "sarif", "-o", str(output), *inputs, cwd=gate_library)
    assert merged.returncode == 2
    assert line in merged.stderr and "Traceback" not in merged.stderr, merged.stderr
    assert output.read_text() == "the previous result\n"


def test_an_empty_shard_is_a_result_too(tmp_path):
    write(tmp_path, "only.obj", trapezoids([0.1]))
    listed = shard_files(tmp_path, 3, "only.obj")
    assert sorted(map(len, listed)) == [0, 0, 1]
    results = check_shards(tmp_path, 3, tmp_path, paths=("only.obj",))
    empty = [json.loads(r.read_text()) for r in results if not json.loads(r.read_text())["files"]]
    assert len(empty) == 2 and all(doc["shard"]["run_files"] == 1 for doc in empty)
    merged = run("merge", "--format", "json", *map(str, results), cwd=tmp_path)
    whole = run("check", "--format", "json", "only.obj", cwd=tmp_path)
    assert merged.returncode == whole.returncode == 1
    assert json.loads(merged.stdout) == json.loads(whole.stdout)


def test_shards_are_the_same_on_every_machine(tmp_path):
    """Two checkouts in different folders, one checked from its root, one from a subfolder with an absolute
    path: the same files in the same shards, the same run digest."""
    a, b = tmp_path / "a", tmp_path / "b" / "assets"
    for checkout in (a, b):
        checkout.mkdir(parents=True)
        generated_files(checkout)
    (b / "props" / "deep").mkdir()
    (tmp_path / "results-a").mkdir()
    (tmp_path / "results-b").mkdir()
    from_root = [json.loads(r.read_text()) for r in check_shards(a, 3, tmp_path / "results-a")]
    from_below = [json.loads(r.read_text())
                  for r in check_shards(b / "props" / "deep", 3, tmp_path / "results-b", paths=(str(b),))]
    assert [[e["path"] for e in doc["files"]] for doc in from_root] == [
        [Path(e["path"]).relative_to(b).as_posix() for e in doc["files"]] for doc in from_below]
    assert [doc["shard"] for doc in from_root] == [doc["shard"] for doc in from_below]
    assert from_root[0]["shard"]["run_files"] == 7 and all(doc["files"] for doc in from_root)


def test_shards_split_many_files_evenly():
    """4,000 names over 4 shards: each within 3.5 standard deviations (sqrt(4000 * 1/4 * 3/4) = 27.4) of 1,000."""
    counts = Counter(shard_of(f"assets/prop_{i:04d}.obj", 4) for i in range(4000))
    assert sorted(counts) == [1, 2, 3, 4]
    assert all(abs(c - 1000) < 96 for c in counts.values()), counts


def test_shard_numbers_are_pinned():
    """Snapshot (values from this code when it was written): a file moving to another shard between versions
    would send it to another CI job, whose result cache then misses it."""
    assert [shard_of(name, 4) for name in ("a.obj", "props/crate.obj", "characters/hero.usd")] == [3, 4, 1]


def test_merge_keeps_the_baseline_wording(gate_library, tmp_path):
    baseline = tmp_path / "baseline.json"
    assert run("check", "--write-baseline", str(baseline), ".", cwd=gate_library).returncode == 0
    results = check_shards(gate_library, 2, tmp_path, "--baseline", str(baseline))
    merged = run("merge", *map(str, results), cwd=gate_library)
    whole = run("check", "--baseline", str(baseline), ".", cwd=gate_library)
    assert merged.returncode == whole.returncode == 0
    assert merged.stdout == whole.stdout and "No new findings" in merged.stdout


def test_a_shard_cannot_write_the_baseline(gate_library, tmp_path):
    refused = run("check", "--shard", "1/2", "--write-baseline", str(tmp_path / "b.json"), ".", cwd=gate_library)
    assert refused.returncode == 2 and "--write-baseline" in refused.stderr and not (tmp_path / "b.json").exists()
